"""Issue 13: a run whose outputs outgrow the disk. With --out on a small tmpfs the run must exit
3 naming the full disk ("No space left on device"), keep its previous checkpoint intact and
readable (no temporary left behind), and a copy of the run directory on a disk with room must
--resume to the same final state as an uninterrupted run, bit for bit.

Mounting a tmpfs needs root (or CAP_SYS_ADMIN); the test is skipped with the reason otherwise."""
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from test_cli import HB, run  # run(args, cwd): the hardbody binary, captured, 300 s timeout

gsd_hoomd = pytest.importorskip("gsd.hoomd")

# Trajectory frames (~20 kB each, every 0.005) and a checkpoint at every pause of the event loop
# (checkpoint_interval of a microsecond): 1 MiB is full after a few dozen frames.
CONFIG = """
[system]
particles = 108
packing_fraction = 0.3
seed = 11
[shape]
type = "sphere"
radius = 0.5
[run]
equilibrate_time = 0.2
time = 3.0
[output]
log_interval = 0.1
snapshot_interval = 0.005
checkpoint_interval = 1e-6
"""

STATE = ["state_r", "state_v", "state_q", "state_w", "state_t", "state_count", "state_image"]


@pytest.fixture
def small_disk(tmp_path):
    mnt = tmp_path / "small"
    mnt.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(mnt)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {r.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def last_frame(path):
    with gsd_hoomd.open(name=str(path), mode="rb") as t:
        return t[len(t) - 1]


def test_a_full_disk_exits_3_keeps_the_checkpoint_and_resumes_elsewhere(tmp_path, small_disk):
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG)
    out = small_disk / "o"
    r = run(["run", str(cfg), "--out", str(out), "--quiet"], tmp_path)
    assert r.returncode == 3, (r.returncode, r.stderr)
    assert "No space left on device" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) <= 3, r.stderr  # a message, not a dump

    # The previous checkpoint is intact: it reads back, and no temporary is left on the disk.
    ck = out / "checkpoint.gsd"
    assert ck.exists(), sorted(p.name for p in out.iterdir())
    f = last_frame(ck)
    assert f.particles.N == 108
    for k in STATE:
        assert f.log["particles/hardbody/" + k].shape[0] == 108, k
    assert not (out / "checkpoint.gsd.tmp").exists()

    # The run directory, copied to a disk with room, resumes and completes ...
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    r = run(["run", str(cfg), "--out", str(copy), "--resume", "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr

    # ... with the final state of an uninterrupted run.
    r = run(["run", str(cfg), "--out", str(tmp_path / "ref"), "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr
    a, b = last_frame(copy / "checkpoint.gsd"), last_frame(tmp_path / "ref" / "checkpoint.gsd")
    assert a.log["hardbody/time"][0] == b.log["hardbody/time"][0]
    for k in STATE:
        assert np.array_equal(a.log["particles/hardbody/" + k], b.log["particles/hardbody/" + k]), k
    ta, tb = last_frame(copy / "trajectory.gsd"), last_frame(tmp_path / "ref" / "trajectory.gsd")
    assert np.array_equal(ta.log["particles/hardbody/position_double"],
                          tb.log["particles/hardbody/position_double"])
    rows = lambda d: (d / "log.tsv").read_text().splitlines()
    assert rows(copy) == rows(tmp_path / "ref")
