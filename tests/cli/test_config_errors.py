"""Issue 13 regressions of config validation in `hardbody run`: every unknown key in one message,
--set errors named by the option, a directory or missing path as the config, shortest round-trip
floats in config.resolved.toml, extreme packing fractions, and resource estimates (memory and
output volume) refused up front. Each exits 2 with one message line and leaves nothing behind, or
runs. Each test failed on the commit before its fix."""
import math
import re
import struct
import tomllib
from pathlib import Path

import pytest

from test_cli import HB, run  # run(args, cwd): the hardbody binary, captured, 300 s timeout

SPHERES = """[system]
particles = 108
packing_fraction = 0.3
seed = 3
[shape]
type = "sphere"
radius = 0.5
[run]
equilibrate_time = 0.1
time = 0.3
[output]
log_interval = 0.1
snapshot_interval = 0.1
"""


def refused(tmp_path, args, text=SPHERES):
    """Runs `hardbody run c.toml ARGS` (--out o): exit 2, one line, nothing written. The line."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(text)
    r = run(["run", str(cfg), "--out", "o", "--quiet", *args], tmp_path)
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = [l for l in r.stderr.splitlines() if l.strip()]
    assert len(lines) == 1, r.stderr
    assert not (tmp_path / "o").exists()
    return lines[0]


def test_every_unknown_key_in_one_message(tmp_path):
    text = SPHERES.replace("seed = 3", "sed = 3").replace("time = 0.3", "time = 0.3\ncolour = 1")
    text += "[observable]\ninterval = 0.1\n"
    line = refused(tmp_path, [], text)
    assert "c.toml:4: unknown key 'system.sed' (did you mean 'system.seed'?)" in line
    assert "c.toml:11: unknown key 'run.colour'" in line
    assert "c.toml:15: unknown section or key 'observable' (did you mean [observables]?)" in line


def test_a_key_in_the_wrong_section_is_pointed_to_its_section(tmp_path):
    line = refused(tmp_path, [], SPHERES.replace("seed = 3", "seed = 3\nlog_interval = 0.5"))
    assert "c.toml:5: unknown key 'system.log_interval' (did you mean 'output.log_interval'?)" in line


@pytest.mark.parametrize("option,expect", [
    ("system.seed=abc", "key 'system.seed': must be an integer"),
    ("system.packing_fraction=0.9", "key 'system.packing_fraction': 0.9 is not below"),
    ("run.time=-1", "key 'run.time': must be positive"),
    ("system.sed=4", "unknown key 'system.sed' (did you mean 'system.seed'?)"),
])
def test_set_errors_are_reported_against_the_option(tmp_path, option, expect):
    line = refused(tmp_path, ["--set", option])
    assert line.startswith(f"hardbody: error: --set {option}: {expect}"), line
    assert "c.toml" not in line  # the key is also in the file: its line is not the problem


def test_a_directory_as_config_is_named_as_such(tmp_path):
    (tmp_path / "cfgdir").mkdir()
    r = run(["run", "cfgdir", "--out", "o"], tmp_path)
    assert r.returncode == 2 and r.stderr.strip() == "hardbody: error: cfgdir: is a directory, not a config file", r.stderr
    r = run(["run", "missing.toml", "--out", "o"], tmp_path)
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip() == "hardbody: error: missing.toml: cannot open config file (No such file or directory)"
    assert not (tmp_path / "o").exists()


def bits(x):
    return struct.pack("<d", float(x))


def test_resolved_config_floats_are_shortest_and_round_trip(tmp_path):
    third = 1 / 3
    text = (SPHERES.replace("packing_fraction = 0.3", "packing_fraction = 0.1")
            .replace("[output]", f"[output]\ncheckpoint_interval = {third!r}")
            + f"[observables]\nq = {7 / 3!r}\ninterval = 0.05\nmax_lag = 0.15\n")
    cfg = tmp_path / "c.toml"
    cfg.write_text(text)
    r = run(["run", str(cfg), "--out", "o", "--quiet", "--set", "system.temperature=0.7"], tmp_path)
    assert r.returncode == 0, r.stderr
    resolved_text = (tmp_path / "o" / "config.resolved.toml").read_text()
    assert not re.search(r"\d{12,}", resolved_text.replace(repr(third), "").replace(repr(7 / 3), "")), resolved_text
    assert "packing_fraction = 0.1\n" in resolved_text and f"checkpoint_interval = {third!r}\n" in resolved_text
    resolved = tomllib.loads(resolved_text)
    given = tomllib.loads(text)
    given["system"]["temperature"] = 0.7
    # every value of the config, and the defaults, bit for bit
    expected = {**{(s, k): v for s, t in given.items() for k, v in t.items()},
                ("solver", "eps_d"): 1e-5, ("neighbors", "shell"): 0.15, ("init", "phi0"): 0.1,
                ("init", "growth_rate"): 0.05, ("output", "max_output_gb"): 20.0}
    for (s, k), v in expected.items():
        got = resolved[s][k]
        assert type(got) is type(v) and (bits(got) == bits(v) if isinstance(v, float) else got == v), (s, k, got, v)
    assert bits(resolved["shape"]["inertia"]) == bits(0.4 * 0.5 ** 2)
    # and it runs again as is, to the same result
    r2 = run(["run", str(tmp_path / "o" / "config.resolved.toml"), "--out", "again", "--quiet"], tmp_path)
    assert r2.returncode == 0, r2.stderr
    assert (tmp_path / "again" / "config.resolved.toml").read_text() == resolved_text


EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SMALL = ["--set", "run.time=0.05", "--set", "run.equilibrate_time=0.02", "--set", "output.log_interval=0.025"]


# The other shapes' start is also checked for overlaps by for_close_pairs
# (src/observers/overlap.cpp), whose own cell grid is capped the same way.
@pytest.mark.parametrize("example,particles", [
    ("hard-spheres", 108),
    ("ellipsoids", 64),
    ("superquadrics", 64),
    ("binary-spheres", None)])
def test_a_dilute_box_runs(tmp_path, example, particles):
    """phi = 1e-9: the cell grid once asked for ~1e11 cells (std::bad_alloc, exit 3)."""
    args = ["--set", "system.packing_fraction=1e-9", *SMALL]
    if particles:
        args += ["--set", f"system.particles={particles}"]
    r = run(["run", str(EXAMPLES / f"{example}.toml"), "--out", "o", "--quiet", *args], tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "o" / "summary.json").is_file()


@pytest.mark.parametrize("phi,particles,status", [(0.7399, 108, 0), (0.7405, 108, 2), (0.3, 1, 2)])
def test_dense_and_single_body_starts(tmp_path, phi, particles, status):
    args = ["--set", f"system.packing_fraction={phi}", "--set", f"system.particles={particles}",
            "--set", "run.time=0.01", "--set", "run.equilibrate_time=0"]
    r = run(["run", str(EXAMPLES / "hard-spheres.toml"), "--out", "o", "--quiet", *args], tmp_path)
    assert r.returncode == status, r.stderr
    if status == 2:
        lines = [l for l in r.stderr.splitlines() if l.strip()]
        assert len(lines) == 1 and "system." in lines[0], r.stderr
        assert not (tmp_path / "o").exists()


def mem_available():
    for line in Path("/proc/meminfo").read_text().splitlines():
        if line.startswith("MemAvailable:"):
            return int(line.split()[1]) * 1024
    return 0


def test_a_run_that_cannot_fit_in_memory_is_refused_before_any_work(tmp_path):
    """N = 1e8 spheres was accepted and died after 40 s at 12.5 GB with std::bad_alloc (exit 3)."""
    if not 0 < mem_available() < 100e9:  # the estimate is well above 100 GB
        pytest.skip("needs a machine with less than 100 GB available")
    line = refused(tmp_path, ["--set", "system.particles=100000000"])
    m = re.search(r"key 'system.particles': the run needs about ([\d.]+) GB of memory .* more than the ([\d.]+) GB available", line)
    assert m, line
    assert float(m.group(1)) > float(m.group(2))


def test_an_output_volume_beyond_the_limit_is_refused(tmp_path):
    """snapshot_interval = 1e-9 was accepted and wrote 700 MB a minute."""
    line = refused(tmp_path, ["--set", "output.snapshot_interval=1e-9", "--set", "run.time=50"])
    assert re.search(r"c\.toml: output\.snapshot_interval = 1e-09: 5e\+10 trajectory frames, [\d.e+]+ GB: the run would "
                     r"write about [\d.e+]+ GB in all, more than output.max_output_gb = 20", line), line
    # the limit is a key: a tiny one refuses this small run, the default runs it
    line = refused(tmp_path, ["--set", "output.max_output_gb=1e-6"])
    assert "more than output.max_output_gb = 1e-06" in line
    cfg = tmp_path / "c.toml"
    assert run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path).returncode == 0
