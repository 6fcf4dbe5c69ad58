"""Issue 13 regressions of `hardbody run`: nothing lost, nothing overwritten, every bad output
path and every damaged or changed resume refused up front (exit 2, one message), log blocks and
errors that say what they know, the final state in the trajectory, finished runs resumed or
extended. Each test failed on the commit before its fix."""
import json
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from test_cli import HB, run  # run(args, cwd): the hardbody binary, captured, 300 s timeout

SPHERES = """
[system]
particles = 108
packing_fraction = 0.3
seed = 3
[shape]
type = "sphere"
radius = 0.5
[run]
equilibrate_time = 0.3
time = {time}
[output]
log_interval = 0.1
snapshot_interval = 0.5
"""


def config(tmp_path, time=1.0, text=SPHERES):
    cfg = tmp_path / "c.toml"
    cfg.write_text(text.format(time=time))
    return cfg


def summary(d):
    return json.loads((d / "summary.json").read_text())


def test_set_may_come_before_the_config_path(tmp_path):
    cfg = config(tmp_path)
    r = run(["run", "--set", "run.time=0.5", str(cfg), "--out", "o", "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert abs(summary(tmp_path / "o")["time"] - 0.5) < 1e-9


def test_an_existing_run_is_refused_unless_resume_or_overwrite(tmp_path):
    cfg = config(tmp_path, 0.5)
    assert run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path).returncode == 0
    first = (tmp_path / "o" / "summary.json").read_bytes()
    (tmp_path / "o" / "stale.png").write_text("a plot of the old run")
    r = run(["run", str(cfg), "--out", "o", "--quiet", "--set", "system.seed=4"], tmp_path)
    assert r.returncode == 2 and "--overwrite" in r.stderr and "--resume" in r.stderr, r.stderr
    assert (tmp_path / "o" / "summary.json").read_bytes() == first
    r = run(["run", str(cfg), "--out", "o", "--quiet", "--overwrite", "--set", "system.seed=4"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert summary(tmp_path / "o")["seed"] == 4
    assert not (tmp_path / "o" / "stale.png").exists()  # nothing of the old run survives
    # a directory that holds something else is never emptied, even with --overwrite
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "thesis.tex").write_text("precious")
    r = run(["run", str(cfg), "--out", "mine", "--quiet", "--overwrite"], tmp_path)
    assert r.returncode == 2 and "holds no hardbody run" in r.stderr, r.stderr
    assert (tmp_path / "mine" / "thesis.tex").read_text() == "precious"


@pytest.mark.parametrize("out,expect", [("", "empty path"), ("afile", "not a directory"),
                                        ("afile/sub", "cannot create")])
def test_bad_output_paths_exit_2_before_any_work(tmp_path, out, expect):
    (tmp_path / "afile").write_text("x")
    # an ellipsoid start that grows: the path must be refused before the growth begins
    cfg = config(tmp_path, text=SPHERES.replace('type = "sphere"\nradius = 0.5',
                                                'type = "ellipsoid"\nsemi_axes = [1.0, 0.5, 0.5]')
                 .replace("packing_fraction = 0.3", "packing_fraction = 0.5").replace("108", "256"))
    before = sorted(p.name for p in tmp_path.iterdir())
    r = run(["run", str(cfg), "--out", out], tmp_path)
    assert r.returncode == 2 and expect in r.stderr, r.stderr
    assert "growing" not in r.stderr  # refused before the start was built
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_two_runs_on_one_directory_are_refused(tmp_path):
    cfg = config(tmp_path, 1e5)
    p = subprocess.Popen([HB, "run", str(cfg), "--out", "o", "--quiet"], cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        for _ in range(300):  # wait (at most 30 s) until the first run has written its config
            if (tmp_path / "o" / "config.resolved.toml").exists():
                break
            time.sleep(0.1)
        for extra in [["--resume"], ["--overwrite"]]:
            r = run(["run", str(cfg), "--out", "o", "--quiet", *extra], tmp_path)
            assert r.returncode == 2 and "in use by another hardbody run" in r.stderr, r.stderr
        assert p.poll() is None  # the first run goes on
    finally:
        p.send_signal(signal.SIGTERM)
        p.communicate(timeout=60)
    assert p.returncode == 128 + signal.SIGTERM
    # the lock died with its process: this resume gets past it (and is refused for its own
    # reason: it would shorten the run below the checkpoint's time)
    r = run(["run", str(cfg), "--out", "o", "--quiet", "--resume", "--set", "run.time=0.01"], tmp_path)
    assert r.returncode == 2 and "in use" not in r.stderr and "may only extend" in r.stderr, r.stderr


def test_log_interval_not_exact_in_binary_gives_whole_blocks(tmp_path):
    cfg = config(tmp_path, 1.0)  # 10 x 0.1 sums to 0.9999999999999999
    assert run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path).returncode == 0
    s = summary(tmp_path / "o")
    assert s["Z_blocks"] == 10
    rows = (tmp_path / "o" / "log.tsv").read_text().splitlines()[1:]
    assert len(rows) == 10
    assert all(abs(float(r.split("\t")[0]) - 0.1 * (k + 1)) < 1e-9 for k, r in enumerate(rows))


def test_error_of_a_single_block_is_unknown(tmp_path):
    cfg = config(tmp_path, 0.05)
    r = run(["run", str(cfg), "--out", "o"], tmp_path)
    assert r.returncode == 0, r.stderr
    s = summary(tmp_path / "o")
    assert s["Z_blocks"] == 1 and s["Z_error"] is None and s["collision_rate_error"] is None
    assert any("fewer" in n or "at least 2" in n for n in s["notes"])
    assert "+- unknown" in r.stderr


def test_final_state_is_the_last_frame(tmp_path):
    gsd_hoomd = pytest.importorskip("gsd.hoomd")
    cfg = config(tmp_path, 1.2)  # snapshots at 0, 0.5, 1.0; the end 1.2 is off the grid
    assert run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path).returncode == 0
    with gsd_hoomd.open(str(tmp_path / "o" / "trajectory.gsd"), mode="rb") as t:
        times = [float(f.log["hardbody/time"][0]) for f in t]
    assert len(times) == summary(tmp_path / "o")["trajectory_frames"] == 4
    assert abs(times[-1] - (0.3 + 1.2)) < 1e-12


def test_finished_run_resumes_to_nothing_and_extends(tmp_path):
    cfg = config(tmp_path, 1.0)
    assert run(["run", str(cfg), "--out", "a", "--quiet"], tmp_path).returncode == 0
    first = (tmp_path / "a" / "summary.json").read_bytes()
    r = run(["run", str(cfg), "--out", "a", "--resume"], tmp_path)
    assert r.returncode == 0 and "finished" in r.stderr and "run.time" in r.stderr, r.stderr
    assert (tmp_path / "a" / "summary.json").read_bytes() == first
    # extended to 2.0: the same measured run as one of 2.0 from the start
    r = run(["run", str(cfg), "--out", "a", "--resume", "--quiet", "--set", "run.time=2.0"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert run(["run", str(cfg), "--out", "b", "--quiet", "--set", "run.time=2.0"], tmp_path).returncode == 0
    a, b = summary(tmp_path / "a"), summary(tmp_path / "b")
    for k in ["collisions", "Z", "Z_error", "Z_blocks", "energy_drift", "min_distance"]:
        assert a[k] == b[k], k
    assert (tmp_path / "a" / "log.tsv").read_text() == (tmp_path / "b" / "log.tsv").read_text()


def test_kill_between_log_commit_and_summary_is_recoverable(tmp_path):
    cfg = config(tmp_path, 1.0)
    assert run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path).returncode == 0
    want = summary(tmp_path / "o")
    (tmp_path / "o" / "summary.json").unlink()  # the window: log.tsv committed, no summary yet
    r = run(["run", str(cfg), "--out", "o", "--resume", "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr
    got = summary(tmp_path / "o")
    for k in ["collisions", "Z", "Z_error", "energy_drift", "trajectory_frames"]:
        assert got[k] == want[k], k


def test_resume_refuses_every_changed_measurement_key(tmp_path):
    cfg = config(tmp_path, 1.0)
    assert run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path).returncode == 0
    ck = (tmp_path / "o" / "checkpoint.gsd").read_bytes()
    r = run(["run", str(cfg), "--out", "o", "--resume", "--set", "run.equilibrate_time=1",
             "--set", "output.log_interval=0.2"], tmp_path)
    assert r.returncode == 2, r.stderr
    assert "run.equilibrate_time" in r.stderr and "output.log_interval" in r.stderr, r.stderr
    assert (tmp_path / "o" / "checkpoint.gsd").read_bytes() == ck


def rewrite_checkpoint(path, edit):
    """Copy every chunk of the one-frame checkpoint, passing state arrays through edit(name, array)."""
    gsd_fl = pytest.importorskip("gsd.fl")
    with gsd_fl.open(str(path), "rb") as f:
        chunks = {n: f.read_chunk(0, n) for n in f.find_matching_chunk_names("")}
        meta = (f.application, f.schema, f.schema_version)
    path.unlink()
    with gsd_fl.open(str(path), "xb", application=meta[0], schema=meta[1], schema_version=meta[2]) as f:
        for n, a in chunks.items():
            f.write_chunk(n, edit(n, np.array(a)))
        f.end_frame()


@pytest.mark.parametrize("damage,expect", [("nan", "non-finite"), ("overlap", "overlapping")])
def test_resume_refuses_a_damaged_state(tmp_path, damage, expect):
    cfg = config(tmp_path, 1e5)
    p = subprocess.Popen([HB, "run", str(cfg), "--out", "o", "--quiet"], cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    p.send_signal(signal.SIGTERM)
    p.communicate(timeout=60)
    if p.returncode == 0:
        pytest.skip("the run finished before the signal")
    ck = tmp_path / "o" / "checkpoint.gsd"

    def edit(name, a):
        if damage == "nan" and name.endswith("hardbody/state_v"):
            a[5, 1] = np.nan
        if damage == "overlap":  # body 1 on body 0's trajectory
            for k in ["state_r", "state_v", "state_t"]:
                if name.endswith("hardbody/" + k):
                    a[1] = a[0]
        return a

    rewrite_checkpoint(ck, edit)
    damaged = ck.read_bytes()
    r = run(["run", str(cfg), "--out", "o", "--resume", "--quiet"], tmp_path)
    assert r.returncode == 2 and expect in r.stderr and "checkpoint.gsd" in r.stderr, r.stderr
    assert ck.read_bytes() == damaged  # nothing written
