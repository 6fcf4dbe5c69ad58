"""Checkpoint/restart: `--resume` after SIGINT or SIGKILL reproduces the uninterrupted run bit
for bit (final state, log, summary); bad checkpoints exit 2 and are never destroyed."""
import json
import os
import signal
import subprocess
import time
from pathlib import Path

import gsd.hoomd
import numpy as np
import pytest

HB = os.environ.get("HARDBODY", "hardbody")

CFG = """
[system]
particles = 2048
packing_fraction = 0.42
seed = 9
[shape]
type = "sphere"
radius = 0.5
[run]
equilibrate_time = 1.0
time = 60.0
[neighbors]
method = "{method}"
shell = 0.2
[output]
log_interval = 0.5
snapshot_interval = 4.0
checkpoint_interval = 0.2
"""


def run(args, cwd, **kw):
    return subprocess.run([HB, *args], cwd=cwd, capture_output=True, text=True, timeout=600, **kw)


def final_state(d):
    with gsd.hoomd.open(str(d / "checkpoint.gsd"), mode="rb") as t:
        f = t[-1]
        return {k: np.asarray(v) for k, v in f.log.items() if k.startswith("particles/hardbody/")}


def interrupted_run(cfg, out, cwd, sig, delay):
    p = subprocess.Popen([HB, "run", str(cfg), "--out", str(out), "--quiet"], cwd=cwd,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    p.send_signal(sig)
    _, err = p.communicate(timeout=600)
    return p.returncode, err


@pytest.mark.parametrize("method", ["cells", "nnl"])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_resume_reproduces_uninterrupted_run(tmp_path, method, sig):
    cfg = tmp_path / "c.toml"
    cfg.write_text(CFG.format(method=method))
    full = run(["run", str(cfg), "--out", "full", "--quiet"], tmp_path)
    assert full.returncode == 0, full.stderr
    code, err = interrupted_run(cfg, tmp_path / "part", tmp_path, sig, 1.0)
    if code == 0:
        pytest.skip("the run finished before the signal; machine too fast for this test")
    assert code == (-sig if sig == signal.SIGKILL else 128 + sig), (code, err)
    if sig != signal.SIGKILL:
        assert "checkpoint written" in err
    assert (tmp_path / "part" / "checkpoint.gsd").is_file()
    assert not (tmp_path / "part" / "summary.json").exists()
    res = run(["run", str(cfg), "--out", "part", "--resume", "--quiet"], tmp_path)
    assert res.returncode == 0, res.stderr
    a, b = final_state(tmp_path / "full"), final_state(tmp_path / "part")
    assert a.keys() == b.keys()
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    assert (tmp_path / "full" / "log.tsv").read_text() == (tmp_path / "part" / "log.tsv").read_text()
    sa = json.loads((tmp_path / "full" / "summary.json").read_text())
    sb = json.loads((tmp_path / "part" / "summary.json").read_text())
    for k in ["collisions", "Z", "Z_error", "energy_drift", "events", "trajectory_frames", "min_distance"]:
        assert sa[k] == sb[k], k
    with gsd.hoomd.open(str(tmp_path / "full" / "trajectory.gsd"), mode="rb") as ta, \
            gsd.hoomd.open(str(tmp_path / "part" / "trajectory.gsd"), mode="rb") as tb:
        assert len(ta) == len(tb) == sa["trajectory_frames"]
        for fa, fb in zip(ta, tb):
            assert np.array_equal(fa.particles.position, fb.particles.position)
            assert np.array_equal(fa.log["particles/hardbody/position_double"],
                                  fb.log["particles/hardbody/position_double"])


def test_trajectory_fields_for_ovito(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(CFG.format(method="cells").replace("time = 60.0", "time = 8.0"))
    r = run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr
    with gsd.hoomd.open(str(tmp_path / "o" / "trajectory.gsd"), mode="rb") as t:
        assert len(t) == 3  # t = 0 and 4 on the snapshot grid, then the final state (t = 8)
        f = t[1]
        L = f.configuration.box[:3]
        assert f.particles.N == 2048
        assert f.particles.types == ["sphere"]
        assert f.particles.type_shapes == [{"type": "Sphere", "diameter": 1.0}]
        pos = f.particles.position
        assert np.all(np.abs(pos) <= L / 2 + 1e-4)  # HOOMD convention: centred box
        exact = f.log["particles/hardbody/position_double"]
        assert np.allclose(exact - L / 2, pos, atol=1e-5)
        assert f.particles.orientation.shape == (2048, 4)
        assert abs(float(f.log["hardbody/time"][0]) - 5.0) < 1e-12


def test_bad_checkpoints_exit_2_and_are_kept(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(CFG.format(method="cells").replace("time = 60.0", "time = 2.0"))
    assert run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path).returncode == 0
    ck = tmp_path / "o" / "checkpoint.gsd"
    good = ck.read_bytes()
    # a different configuration
    r = run(["run", str(cfg), "--out", "o", "--resume", "--set", "system.seed=10"], tmp_path)
    assert r.returncode == 2 and "different configuration" in r.stderr and "system.seed" in r.stderr, r.stderr
    assert ck.read_bytes() == good
    # truncated
    ck.write_bytes(good[: len(good) // 2])
    r = run(["run", str(cfg), "--out", "o", "--resume"], tmp_path)
    assert r.returncode == 2 and "checkpoint.gsd" in r.stderr, r.stderr
    assert ck.read_bytes() == good[: len(good) // 2]
    # garbage
    ck.write_bytes(b"not a gsd file at all" * 10)
    r = run(["run", str(cfg), "--out", "o", "--resume"], tmp_path)
    assert r.returncode == 2 and "checkpoint.gsd" in r.stderr, r.stderr
    # missing
    r = run(["run", str(cfg), "--out", "nothing-here", "--resume"], tmp_path)
    assert r.returncode == 2 and "no checkpoint" in r.stderr, r.stderr


ELLIPSOIDS = """
[system]
particles = 256
packing_fraction = 0.3
seed = 2
[shape]
type = "ellipsoid"
semi_axes = [1.0, 0.5, 0.5]
[run]
equilibrate_time = 0.5
time = 6.0
[neighbors]
method = "{method}"
[output]
log_interval = 0.25
snapshot_interval = 1.0
checkpoint_interval = 0.2
"""


def sigterm_resume(tmp_path, text, delay):
    """The config run whole ("full") and stopped by SIGTERM after `delay` s then resumed ("part"):
    asserts the final checkpoint states are equal; returns both summaries."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(text)
    full = run(["run", str(cfg), "--out", "full", "--quiet"], tmp_path)
    assert full.returncode == 0, full.stderr
    code, err = interrupted_run(cfg, tmp_path / "part", tmp_path, signal.SIGTERM, delay)
    if code == 0:
        pytest.skip("the run finished before the signal")
    assert code == 128 + signal.SIGTERM, (code, err)
    res = run(["run", str(cfg), "--out", "part", "--resume", "--quiet"], tmp_path)
    assert res.returncode == 0, res.stderr
    a, b = final_state(tmp_path / "full"), final_state(tmp_path / "part")
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    return (json.loads((tmp_path / "full" / "summary.json").read_text()),
            json.loads((tmp_path / "part" / "summary.json").read_text()))


@pytest.mark.parametrize("method", ["cells", "nnl"])
def test_ellipsoid_resume_reproduces_uninterrupted_run(tmp_path, method):
    sa, sb = sigterm_resume(tmp_path, ELLIPSOIDS.format(method=method), 2.0)
    assert sa["collisions"] == sb["collisions"] and sa["Z"] == sb["Z"] and sa["overlaps"] == 0
    assert sa["neighbors"] == method


WALLS = """
[system]
particles = 200
packing_fraction = 0.3
seed = 4
[shape]
type = "ellipsoid"
semi_axes = [1.5, 0.5, 0.5]
[box]
aspect = [1.0, 1.0, 1.5]
[walls]
planes = ["z"]
[thermostat]
type = "andersen"
rate = 0.2
during = "always"
[run]
equilibrate_time = 5.0
time = 30.0
[neighbors]
method = "nnl"
[output]
log_interval = 1.0
snapshot_interval = 1.0
checkpoint_interval = 0.2
"""


def test_walls_and_thermostat_resume_reproduces_uninterrupted_run(tmp_path):
    """Walls (their pressure and profiles) and the Andersen thermostat (each body's next event
    and event count) continue bit for bit after a SIGTERM."""
    sa, sb = sigterm_resume(tmp_path, WALLS, 3.0)
    for k in ["collisions", "Z", "wall_pressure", "wall_pressure_error", "events", "temperature"]:
        assert sa[k] == sb[k], k
    assert sa["events"]["thermostat"] > 0 and sa["events"]["wall"] > 0
    assert sa["overlaps"] == 0 and sa["wall_penetrations"] == 0
    for f in ["density_profile.tsv", "order_profile.tsv"]:
        assert (tmp_path / "full" / f).read_text() == (tmp_path / "part" / f).read_text(), f
