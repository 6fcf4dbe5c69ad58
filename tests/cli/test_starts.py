"""Issue 13 regressions of the starts: growth that detects jamming and names the reached phi,
hard spheres grown from a random placement (a fluid start for metastable states), elongated
bodies that no longer need a 10:1 stretched lattice, and notes where the start differs from the
asked one. Each test failed on the commit before its fix."""
import json
import subprocess
from pathlib import Path

import pytest

from test_cli import HB, run  # run(args, cwd): the hardbody binary, captured, 300 s timeout

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SHORT = ["--set", "run.time=0.5", "--set", "run.equilibrate_time=0.2", "--set", "output.log_interval=0.1"]


def summary(d):
    return json.loads((d / "summary.json").read_text())


def test_growth_beyond_jamming_stops_with_the_reached_phi(tmp_path):
    """Spheres asked for phi = 0.70 from a random start: the growth once ran forever, printing
    nothing. Now it stops at random close packing (~0.64) with exit 2 and nothing written."""
    r = run(["run", str(EXAMPLES / "hard-spheres.toml"), "--out", "o", "--set", "init.method=grow",
             "--set", "system.packing_fraction=0.70", "--set", "system.particles=108"], tmp_path)
    assert r.returncode == 2, r.stderr
    lines = [l for l in r.stderr.splitlines() if l.startswith("hardbody: error")]
    assert len(lines) == 1 and "system.packing_fraction" in lines[0] and "jammed" in lines[0], r.stderr
    phi = float(lines[0].split("jammed at packing fraction ")[1].split()[0])
    assert 0.60 < phi < 0.68, phi  # random close packing of monodisperse spheres ~0.64
    assert not (tmp_path / "o").exists()


def test_growth_progress_is_shown(tmp_path):
    r = run(["run", str(EXAMPLES / "hard-spheres.toml"), "--out", "o", "--set", "init.method=grow",
             "--set", "system.packing_fraction=0.70", "--set", "system.particles=108"], tmp_path)
    assert "[grow]" in r.stderr and "phi=" in r.stderr, r.stderr


def test_spheres_can_start_from_a_grown_fluid(tmp_path):
    """init.method = "grow" for spheres: random placement grown to phi = 0.54 (a metastable fluid;
    the FCC start stays crystalline there). Crystallinity of the first frame: the structure factor
    at the FCC start's (111) reciprocal vector, S = |sum exp(i k.r)|^2 / N, is O(N) in the crystal
    and O(1) in a fluid."""
    import gsd.hoomd
    import numpy as np

    def s111(d):
        with gsd.hoomd.open(str(d / "trajectory.gsd"), mode="rb") as t:
            x = np.asarray(t[0].log["particles/hardbody/position_double"])
            L = float(t[0].configuration.box[0])
        m = round((len(x) / 4) ** (1 / 3))  # cubic FCC cells per side of the lattice start
        k = 2 * np.pi * m / L * np.array([1.0, 1.0, 1.0])
        return abs(np.exp(1j * x @ k).sum()) ** 2 / len(x)

    args = ["--set", "system.packing_fraction=0.54", "--set", "system.particles=500", *SHORT]
    r = run(["run", str(EXAMPLES / "hard-spheres.toml"), "--out", "o", "--quiet", "--set", "init.method=grow",
             *args], tmp_path)
    assert r.returncode == 0, r.stderr
    s = summary(tmp_path / "o")
    assert s["init"]["method"] == "grow" and s["init"]["placement"] == "random"
    assert s["overlaps"] == 0 and abs(s["packing_fraction"] - 0.54) < 1e-12
    # the default for spheres stays the FCC lattice
    r = run(["run", str(EXAMPLES / "hard-spheres.toml"), "--out", "fcc", "--quiet", *args], tmp_path)
    assert r.returncode == 0, r.stderr
    assert summary(tmp_path / "fcc")["init"]["method"] == "lattice"
    grown, lattice = s111(tmp_path / "o"), s111(tmp_path / "fcc")
    assert lattice > 50 and grown < 10, (lattice, grown)


def test_elongated_bodies_start_in_a_cubic_box(tmp_path):
    """Ellipsoids X0 = 10 at N = 500 were refused ("use more particles"): the lattice start's box
    (19.9 x 21.9 x 23.9 at phi = 0.25) is thinner than two body lengths (20). They now grow from a
    random placement in a cubic box (side 21.9). (A fast growth keeps the test short.)"""
    r = run(["run", str(EXAMPLES / "ellipsoids.toml"), "--out", "o", "--quiet", "--set", "system.particles=500",
             "--set", "shape.semi_axes=[5.0, 0.5, 0.5]", "--set", "system.packing_fraction=0.25",
             "--set", "init.growth_rate=0.5",
             "--set", "run.time=0.2", "--set", "run.equilibrate_time=0.1", "--set", "output.log_interval=0.1"],
            tmp_path)
    assert r.returncode == 0, r.stderr
    s = summary(tmp_path / "o")
    assert s["init"]["placement"] == "random" and s["overlaps"] == 0
    assert s["box"][0] == s["box"][1] == s["box"][2]


def test_too_few_elongated_bodies_are_refused_with_the_real_limit(tmp_path):
    r = run(["run", str(EXAMPLES / "ellipsoids.toml"), "--out", "o", "--set", "system.particles=100",
             "--set", "shape.semi_axes=[5.0, 0.5, 0.5]", "--set", "system.packing_fraction=0.3"], tmp_path)
    assert r.returncode == 2
    assert "minimum image" in r.stderr and "use at least 459 bodies" in r.stderr, r.stderr
    assert not (tmp_path / "o").exists()


def test_a_grow_start_at_or_below_phi0_says_so(tmp_path):
    """phi <= init.phi0 silently switched to the lattice start; summary.json and stderr say it."""
    r = run(["run", str(EXAMPLES / "ellipsoids.toml"), "--out", "o", "--set", "system.packing_fraction=0.05",
             *SHORT], tmp_path)
    assert r.returncode == 0, r.stderr
    assert "note:" in r.stderr and "init.phi0" in r.stderr
    init = summary(tmp_path / "o")["init"]
    assert init["method"] == "lattice" and "init.phi0" in init["note"]


def test_a_run_can_start_from_a_gsd_frame(tmp_path):
    """The CLI could not start from a GSD frame (Python could): init.method = "file". A run
    started from the last frame of another run's trajectory begins exactly in that state; a file
    that does not fit the config is refused naming init.file."""
    import gsd.hoomd
    import numpy as np
    base = ["--set", "system.particles=108", "--set", "system.packing_fraction=0.3", *SHORT]
    r = run(["run", str(EXAMPLES / "ellipsoids.toml"), "--out", "a", "--quiet", *base], tmp_path)
    assert r.returncode == 0, r.stderr
    traj = tmp_path / "a" / "trajectory.gsd"
    start = ["--set", "init.method=file", "--set", f"init.file={traj}", "--set", "run.equilibrate_time=0"]
    r = run(["run", str(EXAMPLES / "ellipsoids.toml"), "--out", "b", "--quiet", *base, *start], tmp_path)
    assert r.returncode == 0, r.stderr
    assert summary(tmp_path / "b")["init"]["method"] == "file"
    with gsd.hoomd.open(str(traj), mode="rb") as ta, \
            gsd.hoomd.open(str(tmp_path / "b" / "trajectory.gsd"), mode="rb") as tb:
        k = "particles/hardbody/"
        assert np.array_equal(ta[-1].log[k + "position_double"], tb[0].log[k + "position_double"])
        # orientations are normalised again when read: equal to rounding
        np.testing.assert_allclose(ta[-1].log[k + "orientation_double"], tb[0].log[k + "orientation_double"],
                                   rtol=0, atol=1e-15)
    r = run(["run", str(EXAMPLES / "ellipsoids.toml"), "--out", "c", *base, *start,
             "--set", "system.particles=100"], tmp_path)
    assert r.returncode == 2 and "init.file" in r.stderr and "108 bodies" in r.stderr, r.stderr
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("walls", ["slit", "container"])
def test_growth_against_walls_stops_when_jammed(tmp_path, walls):
    """The jam test counts wall bounces as ended free flights (half a pair collision each): spheres
    grown towards phi = 0.70 in a slit or in a spherical container stop at a packing that walls
    loosen (random close packing ~0.64 in bulk, lower with walls), with exit 2 and nothing written.
    In the container phi is set by walls.sphere, and the message names that key."""
    cfg = tmp_path / "c.toml"
    if walls == "slit":
        bounds = '[system]\nparticles = 108\npacking_fraction = 0.70\nseed = 1\n[walls]\nplanes = ["z"]\n'
        key = "system.packing_fraction"
    else:
        # R^3 = 3 N v / (4 pi phi) with v = pi / 6: phi = 0.70 for N = 108
        radius = (108 / 8 / 0.70) ** (1 / 3)
        bounds = f"[system]\nparticles = 108\nseed = 1\n[walls]\nsphere = {radius:.12f}\n"
        key = "walls.sphere"
    cfg.write_text(bounds + '[shape]\ntype = "sphere"\nradius = 0.5\n[init]\nmethod = "grow"\n[run]\ntime = 1.0\n')
    r = run(["run", str(cfg), "--out", "o"], tmp_path)
    assert r.returncode == 2, r.stderr
    lines = [l for l in r.stderr.splitlines() if l.startswith("hardbody: error")]
    assert len(lines) == 1 and f"key '{key}'" in lines[0] and "jammed" in lines[0], r.stderr
    phi = float(lines[0].split("jammed at packing fraction ")[1].split()[0])
    assert 0.45 < phi < 0.66, phi
    assert not (tmp_path / "o").exists()
