"""Issue 13 fault injection: SIGTERM and SIGINT in every phase of a run (growth, equilibration,
measurement, checkpoint writing, final output) end it with exit 128 + signal, and `--resume`
then ends in the uninterrupted run's final state bit for bit; SIGKILL at any of these points
(inside a checkpoint write and between the log commit and summary.json included) never stops
`--resume` from completing the same run.

The signals are raised at named points by the run itself (HARDBODY_FAULT="POINT:SIGNAL[:N]",
src/core/fault_injection.hpp), so each phase is hit for sure; signals sent from outside at fixed
random delays cover the moments in between and time the response."""
import json
import os
import random
import signal
import subprocess
import time

import gsd.hoomd
import numpy as np
import pytest

HB = os.environ.get("HARDBODY", "hardbody")

COMMON = """
[system]
particles = {n}
packing_fraction = {phi}
seed = 5
[init]
method = "grow"
phi0 = 0.1
growth_rate = 0.1
[run]
equilibrate_time = 1.0
time = 2.0
[output]
log_interval = 0.25
snapshot_interval = 0.5
checkpoint_interval = 0.02
[observables]
interval = 0.1
max_lag = 1.0
gr_interval = 0.5
"""
SHAPES = {
    "spheres": COMMON.format(n=256, phi=0.45) + '[shape]\ntype = "sphere"\nradius = 0.5\n',
    "ellipsoids": COMMON.format(n=108, phi=0.4) + '[shape]\ntype = "ellipsoid"\nsemi_axes = [1.0, 0.5, 0.5]\n',
}


def hardbody(args, cwd, fault=None, timeout=300):
    env = dict(os.environ)
    env.pop("HARDBODY_FAULT", None)
    if fault:
        env["HARDBODY_FAULT"] = fault
    return subprocess.run([HB, *args], cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env)


def final_state(d):
    """The exact state of the last checkpoint, the log and the physics of summary.json."""
    with gsd.hoomd.open(str(d / "checkpoint.gsd"), mode="rb") as t:
        f = t[-1]
        state = {k: np.asarray(v) for k, v in f.log.items() if k.startswith("particles/hardbody/")}
    s = json.loads((d / "summary.json").read_text())
    physics = {k: s[k] for k in ["collisions", "Z", "Z_error", "energy_drift", "events", "trajectory_frames",
                                 "min_distance", "overlaps"]}
    return state, (d / "log.tsv").read_text(), physics


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = {}
    for name, text in SHAPES.items():
        d = tmp_path_factory.mktemp(name)
        (d / "c.toml").write_text(text)
        r = hardbody(["run", "c.toml", "--out", "full", "--quiet"], d)
        assert r.returncode == 0, r.stderr
        out[name] = final_state(d / "full")
    return out


def same_as_reference(ref, d):
    state, log, physics = final_state(d)
    rstate, rlog, rphysics = ref
    assert state.keys() == rstate.keys()
    for k in state:
        assert np.array_equal(state[k], rstate[k]), k
    assert log == rlog
    assert physics == rphysics


def resume(cwd):
    r = hardbody(["run", "c.toml", "--out", "o", "--quiet", "--resume"], cwd)
    assert r.returncode == 0, r.stderr
    return r


# every run writes at least two checkpoints: one when the start is made, one at the end
POINTS = ["growth", "equilibrate", "measure", "checkpoint:1", "final"]


@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("point", POINTS)
@pytest.mark.parametrize("sig", ["TERM", "INT"])
def test_stop_request_in_every_phase(tmp_path, reference, shape, point, sig):
    (tmp_path / "c.toml").write_text(SHAPES[shape])
    where, _, nth = point.partition(":")
    r = hardbody(["run", "c.toml", "--out", "o", "--quiet"], tmp_path, fault=f"{where}:{sig}:{nth or 1}")
    signo = signal.SIGTERM if sig == "TERM" else signal.SIGINT
    assert r.returncode == 128 + signo, (r.returncode, r.stderr)
    assert f"signal {int(signo)}" in r.stderr, r.stderr
    if where == "growth":
        assert "no checkpoint exists yet" in r.stderr
        assert not (tmp_path / "o" / "checkpoint.gsd").exists()
    elif where == "final":
        assert "complete" in r.stderr and (tmp_path / "o" / "summary.json").is_file()
    else:
        assert "checkpoint written" in r.stderr, r.stderr
        assert not (tmp_path / "o" / "summary.json").exists()
    resume(tmp_path)
    same_as_reference(reference[shape], tmp_path / "o")


@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("point", ["growth", "equilibrate", "measure", "checkpoint:2", "checkpoint-write:2",
                                   "final", "summary"])
def test_kill_anywhere_then_resume_completes(tmp_path, reference, shape, point):
    (tmp_path / "c.toml").write_text(SHAPES[shape])
    where, _, nth = point.partition(":")
    r = hardbody(["run", "c.toml", "--out", "o", "--quiet"], tmp_path, fault=f"{where}:KILL:{nth or 1}")
    assert r.returncode == -signal.SIGKILL, (r.returncode, r.stderr)
    if where == "checkpoint-write":  # the interrupted write left its temporary, not a torn file
        assert (tmp_path / "o" / "checkpoint.gsd").is_file()
    resume(tmp_path)
    same_as_reference(reference[shape], tmp_path / "o")


@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("k", range(4))
def test_signal_from_outside_at_random_moments(tmp_path, reference, shape, k):
    """TERM, INT or KILL after a random delay (fixed seed): a stop request is answered within
    5 s (a bound against hangs, not a speed measure), and the run always resumes to the same end."""
    rng = random.Random(1000 * k + len(shape))
    sig = [signal.SIGTERM, signal.SIGINT, signal.SIGKILL][rng.randrange(3)]
    delay = rng.uniform(0.05, 2.0)
    (tmp_path / "c.toml").write_text(SHAPES[shape])
    env = dict(os.environ)
    env.pop("HARDBODY_FAULT", None)
    p = subprocess.Popen([HB, "run", "c.toml", "--out", "o", "--quiet"], cwd=tmp_path, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    sent = time.monotonic()
    p.send_signal(sig)
    _, err = p.communicate(timeout=300)
    answered = time.monotonic() - sent
    if p.returncode == 0:
        pass  # finished before the signal
    elif sig == signal.SIGKILL:
        assert p.returncode == -signal.SIGKILL
    else:
        assert p.returncode == 128 + sig, (p.returncode, err)
        assert answered < 5.0, f"the stop request took {answered:.1f} s"
    if (tmp_path / "o" / "summary.json").is_file() and p.returncode == 0:
        same_as_reference(reference[shape], tmp_path / "o")
        return
    resume(tmp_path)
    same_as_reference(reference[shape], tmp_path / "o")


@pytest.mark.parametrize("shape", list(SHAPES))
def test_failure_in_the_growth_leaves_the_bodies_and_a_restartable_run(tmp_path, reference, shape):
    """A run-time failure during the growth (a solver failure in the issue's superquadric run)
    exited 3 with nothing written: now the message says where, the bodies at the failure are in
    growth-failure.gsd, and --resume makes the start again."""
    (tmp_path / "c.toml").write_text(SHAPES[shape])
    r = hardbody(["run", "c.toml", "--out", "o", "--quiet"], tmp_path, fault="growth:FAIL:2")
    assert r.returncode == 3, (r.returncode, r.stderr)
    assert "during the growth" in r.stderr and "growth-failure.gsd" in r.stderr, r.stderr
    with gsd.hoomd.open(str(tmp_path / "o" / "growth-failure.gsd"), mode="rb") as t:
        assert len(t) == 1 and t[0].particles.N == (256 if shape == "spheres" else 108)
    resume(tmp_path)
    same_as_reference(reference[shape], tmp_path / "o")


@pytest.mark.parametrize("point", ["equilibrate", "measure"])
def test_failure_in_the_run_writes_a_checkpoint_and_resumes(tmp_path, reference, point):
    (tmp_path / "c.toml").write_text(SHAPES["ellipsoids"])
    r = hardbody(["run", "c.toml", "--out", "o", "--quiet"], tmp_path, fault=f"{point}:FAIL")
    assert r.returncode == 3, (r.returncode, r.stderr)
    assert "injected failure" in r.stderr and "checkpoint written" in r.stderr, r.stderr
    resume(tmp_path)
    same_as_reference(reference["ellipsoids"], tmp_path / "o")


def test_a_non_finite_state_ends_the_run_without_overwriting_the_checkpoint(tmp_path, reference):
    """A NaN in the state (simulated at the 6th finiteness check) once ran on to exit 0 with a
    null Z: now exit 3 naming the body, the previous checkpoint kept, and --resume completes."""
    (tmp_path / "c.toml").write_text(SHAPES["ellipsoids"])
    r = hardbody(["run", "c.toml", "--out", "o", "--quiet"], tmp_path, fault="nonfinite:FAIL:6")
    assert r.returncode == 3, (r.returncode, r.stderr)
    assert "non-finite" in r.stderr and "checkpoint NOT written" in r.stderr, r.stderr
    assert not (tmp_path / "o" / "summary.json").exists()
    resume(tmp_path)
    same_as_reference(reference["ellipsoids"], tmp_path / "o")
