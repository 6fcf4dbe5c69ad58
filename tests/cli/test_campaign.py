"""Issue 14: `hardbody campaign` (python/hardbody_campaign.py through the hardbody binary).

The small campaign examples/campaigns/spheres-small.toml (4 packing fractions x 3 seeds of 108
hard spheres, about a second each) runs locally on 2 cores with Snakemake: results.csv matches
every summary.json, a second invocation starts nothing, a campaign stopped once surely inside a
run (the run frozen while the SIGTERM reaches it) and then killed ten times (SIGTERM and SIGKILL
at seeded random moments) completes on re-run with every run's final state identical to the
uninterrupted campaign's, and a grid point with a config error is reported (message and
reproducer) without stopping the others. Release build only (label integration).
"""
import csv
import json
import os
import random
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from test_cli import HB

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
import campaign_compare  # noqa: E402

EXAMPLE = ROOT / "examples" / "campaigns"


def campaign(args, cwd, timeout=600):
    return subprocess.run([HB, "campaign", *args], cwd=cwd, capture_output=True, text=True, timeout=timeout)


def copy_campaign(dest: Path, extra: str = "") -> Path:
    dest.mkdir(parents=True, exist_ok=True)
    for f in ["spheres-small.toml", "spheres-small-base.toml"]:
        shutil.copy(EXAMPLE / f, dest / f)
    if extra:
        with open(dest / "spheres-small.toml", "a") as f:
            f.write(extra)
    return dest / "spheres-small.toml"


def files_of(d: Path) -> dict:
    """Every file under d (the locks aside) with its bytes and modification time."""
    return {str(p.relative_to(d)): (p.read_bytes(), p.stat().st_mtime_ns)
            for p in sorted(d.rglob("*")) if p.is_file() and p.name != ".hardbody.lock"}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted campaign (12 runs, 2 cores)."""
    d = tmp_path_factory.mktemp("reference")
    cfg = copy_campaign(d)
    r = campaign([str(cfg)], d)
    assert r.returncode == 0, r.stderr
    return d / "spheres-small", r


def test_local_campaign_results_match_summaries(reference):
    out, r = reference
    assert "12 run(s) to go" in r.stderr and "Snakemake" in r.stderr, r.stderr
    rows = list(csv.DictReader(open(out / "results.csv")))
    assert len(rows) == 12
    assert list(rows[0])[:3] == ["system.packing_fraction", "seed", "status"]
    seen = set()
    for row in rows:
        assert row["status"] == "done"
        s = json.loads((out / "runs" / row["run"] / "summary.json").read_text())
        assert abs(float(row["system.packing_fraction"]) - s["packing_fraction"]) < 1e-12  # the box achieved
        assert int(row["seed"]) == s["seed"]
        for k in ["Z", "Z_error", "collision_rate", "collision_rate_error"]:
            assert float(row[k]) == s[k], k  # written with repr: the same double
        assert int(row["collisions"]) == s["collisions"]
        assert "collisions_error" not in row  # the summary has no such key
        seen.add((float(row["system.packing_fraction"]), s["seed"]))
    assert seen == {(p, k) for p in [0.2, 0.3, 0.4, 0.45] for k in [1, 2, 3]}
    pooled = list(csv.DictReader(open(out / "results_pooled.csv")))
    assert len(pooled) == 4 and all(p["seeds"] == "3" for p in pooled)
    for p in pooled:
        zs = [float(r["Z"]) for r in rows if r["system.packing_fraction"] == p["system.packing_fraction"]]
        mean = sum(zs) / 3
        sem = (sum((z - mean) ** 2 for z in zs) / 2 / 3) ** 0.5
        assert abs(float(p["Z"]) - mean) < 1e-12 and abs(float(p["Z_sem"]) - sem) < 1e-12
    for k in ["Z", "collision_rate", "collisions"]:
        assert (out / f"{k}.png").stat().st_size > 1000


def test_rerun_starts_nothing(reference):
    out, _ = reference
    before = files_of(out / "runs")
    r = campaign([str(out.parent / "spheres-small.toml")], out.parent)
    assert r.returncode == 0, r.stderr
    assert "nothing to run (12 of 12 done)" in r.stderr, r.stderr
    assert files_of(out / "runs") == before  # not a byte nor a time stamp changed
    s = campaign(["status", str(out.parent / "spheres-small.toml")], out.parent)
    assert s.returncode == 0 and "12 done, 0 running, 0 failed, 0 pending" in s.stdout, s.stdout


def hardbody_runs(out: Path) -> list[tuple[int, str]]:
    """The live `hardbody run` processes of the campaign under `out`: (pid, command line)."""
    res = []
    for p in Path("/proc").iterdir():
        try:
            cmd = (p / "cmdline").read_bytes().split(b"\0")
            state = (p / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except (OSError, IndexError):
            continue
        if state != "Z" and any(str(out).encode() in a for a in cmd) and b"run" in cmd:
            res.append((int(p.name), " ".join(a.decode() for a in cmd)))
    return res


def hardbody_processes(out: Path) -> list[str]:
    return [cmd for _, cmd in hardbody_runs(out)]


def sigterm_pending(pid: int) -> bool:
    """SIGTERM is pending for the process (it cannot act on it while stopped)."""
    bit = 1 << (signal.SIGTERM - 1)
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(("SigPnd:", "ShdPnd:")) and int(line.split()[1], 16) & bit:
            return True
    return False


def stop_campaign_inside_a_run(cfg: Path, out: Path, cwd: Path) -> str:
    """SIGTERM to the campaign while one of its runs is surely in the middle of its work, whatever
    the machine's speed: the run is frozen (SIGSTOP) once its signal handler is installed (it is
    installed before config.resolved.toml is written) and before its summary is written, the
    campaign is told to stop, and the run is thawed once the SIGTERM the campaign passes on is
    pending. Returns the name of that run."""
    p = subprocess.Popen([HB, "campaign", str(cfg)], cwd=cwd, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    frozen = None
    while frozen is None:
        assert time.monotonic() < deadline and p.poll() is None, "no run started"
        for pid, cmd in hardbody_runs(out):
            run_dir = Path(shlex.split(cmd)[shlex.split(cmd).index("--out") + 1])
            if not (run_dir / "config.resolved.toml").exists():
                continue
            try:
                os.kill(pid, signal.SIGSTOP)
            except ProcessLookupError:
                continue
            if (run_dir / "summary.json").exists():  # finishing: let it go, take another
                os.kill(pid, signal.SIGCONT)
                continue
            frozen = (pid, run_dir.name)
            break
        time.sleep(0.01)
    pid, name = frozen
    p.send_signal(signal.SIGTERM)
    while not sigterm_pending(pid):
        assert time.monotonic() < deadline, "the campaign did not pass SIGTERM on to its run"
        time.sleep(0.01)
    os.kill(pid, signal.SIGCONT)
    _, err = p.communicate(timeout=300)
    assert p.returncode == 143, err
    assert hardbody_processes(out) == [], err
    return name


def test_killed_campaign_completes_with_identical_runs(reference, tmp_path):
    ref_out, _ = reference
    cfg = copy_campaign(tmp_path)
    out = tmp_path / "spheres-small"
    # one stop surely inside a run, then ten at seeded random moments (how many of those land
    # inside a run depends on the machine's speed)
    stopped = stop_campaign_inside_a_run(cfg, out, tmp_path)
    assert "== exit 143" in (out / "logs" / f"{stopped}.log").read_text()
    rng = random.Random(14)
    for k in range(10):
        p = subprocess.Popen([HB, "campaign", str(cfg)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True)
        time.sleep(rng.uniform(1.5, 5.0))
        sig = signal.SIGTERM if k % 2 == 0 else signal.SIGKILL
        p.send_signal(sig)
        _, err = p.communicate(timeout=300)
        if sig == signal.SIGTERM:
            # stopped (the handler answers 128 + 15), finished before the signal (0), or killed
            # before its handler was installed (-15: nothing had started yet)
            assert p.returncode in (143, 0, -15), err
            if p.returncode == 143:  # every run it had started stopped with its checkpoint
                assert hardbody_processes(out) == [], err
        # after SIGKILL the runs go on; the next invocation stops them (SIGTERM, checkpoint)
    r = campaign([str(cfg)], tmp_path)
    assert r.returncode == 0, r.stderr
    logs = "".join(p.read_text() for p in (out / "logs").glob("*.log"))
    # runs were interrupted and resumed; the identity with the uninterrupted campaign is the test
    assert logs.count("== exit 143") >= 1, logs
    assert "--resume" in logs
    assert campaign_compare.compare(ref_out, out) == []
    rows = list(csv.DictReader(open(out / "results.csv")))
    ref_rows = list(csv.DictReader(open(ref_out / "results.csv")))
    assert rows == ref_rows


def test_failing_grid_point_is_reported_and_the_others_run(tmp_path):
    cfg = tmp_path / "bad.toml"
    shutil.copy(EXAMPLE / "spheres-small-base.toml", tmp_path / "base.toml")
    cfg.write_text('base = "base.toml"\nout = "bad"\nseeds = [5]\ncollect = ["Z"]\n'
                   '[set]\n"run.time" = 20.0\n'
                   '[grid]\n"neighbors.method" = ["cells", "octree", "nnl"]\n'
                   '[executor]\njobs = 2\n')
    r = campaign([str(cfg)], tmp_path)
    assert r.returncode == 3, r.stderr
    assert "1 failed" in r.stderr and "method=octree" in r.stderr and "neighbors.method" in r.stderr, r.stderr
    rows = {row["neighbors.method"]: row for row in csv.DictReader(open(tmp_path / "bad" / "results.csv"))}
    assert rows["cells"]["status"] == "done" and rows["nnl"]["status"] == "done"
    assert rows["octree"]["status"] == "failed" and rows["octree"]["Z"] == ""
    st = json.loads((tmp_path / "bad" / "status" / "method=octree,seed=5.json").read_text())
    assert st["exit"] == 2 and "neighbors.method" in st["message"]
    # the reproducer reproduces the failure
    rep = subprocess.run(shlex.split(st["reproducer"]), capture_output=True, text=True, timeout=60)
    assert rep.returncode == 2 and st["message"] in rep.stderr
    s = campaign(["status", str(cfg)], tmp_path)
    assert "2 done, 0 running, 1 failed, 0 pending" in s.stdout and "reproducer:" in s.stdout, s.stdout
    # a failed run is not retried by a plain re-run (a bad input fails again), only when asked
    r2 = campaign([str(cfg)], tmp_path)
    assert r2.returncode == 3 and "nothing to run" in r2.stderr, r2.stderr
    assert st == json.loads((tmp_path / "bad" / "status" / "method=octree,seed=5.json").read_text())
    r3 = campaign([str(cfg), "--retry-failed"], tmp_path)
    assert r3.returncode == 3 and "1 run(s) to go" in r3.stderr, r3.stderr


@pytest.mark.parametrize("text,expect", [
    ('out = "o"\n', "key 'base': required"),
    ('base = "nope.toml"\n', "nope.toml: no such file"),
    ('base = "base.toml"\nsedes = [1]\n', "key 'sedes': unknown key"),
    ('base = "base.toml"\n[grid]\n"system.packing_fraction" = 0.3\n', "key 'grid.system.packing_fraction': expected a non-empty list"),
    ('base = "base.toml"\n[grid]\npacking_fraction = [0.3]\n', "expected a config key 'section.key'"),
    ('base = "base.toml"\n[zip]\n"a.b" = [1, 2]\n"a.c" = [1]\n', "key 'zip': the lists have different lengths"),
    ('base = "base.toml"\n[executor]\ntype = "pbs"\n', "key 'executor.type'"),
    ('base = "base.toml"\n[executor]\ntype = "local"\npartition = "x"\n', "key 'executor.partition': unknown key"),
    ('base = "base.toml"\nseeds = [1, 1]\n', "key 'seeds': a seed is repeated"),
    ('base = "base.toml"\n[grid]\n"system.seed" = [1, 2]\n', "given by the top-level 'seeds'"),
    ('base = "base.toml"\n[grid\n', "bad.toml"),
])
def test_bad_campaign_files_exit_2_with_one_message(tmp_path, text, expect):
    shutil.copy(EXAMPLE / "spheres-small-base.toml", tmp_path / "base.toml")
    (tmp_path / "bad.toml").write_text(text)
    before = sorted(p.name for p in tmp_path.iterdir())
    r = campaign([str(tmp_path / "bad.toml")], tmp_path)
    assert r.returncode == 2, r.stderr
    assert expect in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written


def test_missing_campaign_file_exits_2(tmp_path):
    r = campaign([str(tmp_path / "none.toml")], tmp_path)
    assert r.returncode == 2 and "none.toml: cannot open" in r.stderr, r.stderr
    r = campaign(["status", str(tmp_path)], tmp_path)
    assert r.returncode == 2 and "is a directory" in r.stderr, r.stderr
    r = campaign([], tmp_path)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "give a campaign file" in r.stderr, r.stderr


def test_plot_series_ignore_keys_zipped_with_x(tmp_path):
    """The equation-of-state campaign zips run.time with phi: one series, not one per phi."""
    import hardbody_campaign as hc
    c = hc.load(EXAMPLE / "eos-ellipsoids.toml")
    assert hc.plot_axes(c) == ("system.packing_fraction", [])
    assert len(c.runs) == 36 and c.runs[0].name == "packing_fraction=0.01,time=2000.0,seed=1"
    shutil.copy(EXAMPLE / "spheres-small-base.toml", tmp_path / "base.toml")
    (tmp_path / "g.toml").write_text('base = "base.toml"\n[grid]\n"neighbors.method" = ["cells", "nnl"]\n'
                                     '[zip]\n"system.packing_fraction" = [0.1, 0.2]\n"run.time" = [2.0, 1.0]\n'
                                     '[plot]\nx = "system.packing_fraction"\n')
    assert hc.plot_axes(hc.load(tmp_path / "g.toml")) == ("system.packing_fraction", ["neighbors.method"])
