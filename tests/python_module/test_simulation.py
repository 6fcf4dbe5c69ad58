"""hardbody.Simulation: building from a config, running, state arrays, observables, errors."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

import hardbody


def sphere_config(n=500, phi=0.3, seed=7, **sections):
    cfg = {
        "system": {"particles": n, "packing_fraction": phi, "seed": seed},
        "shape": {"type": "sphere", "radius": 0.5},
    }
    cfg.update(sections)
    return cfg


def z_hansen_goos(phi):
    """Hansen-Goos (J. Chem. Phys. 144, 164506 (2016)) hard-sphere equation of state."""
    b = [9, -19, 47.0 / 3.0, -2.635232, -1.265575, 0.041212, 0.248245, -0.096495]
    s = sum(bk * phi**k for k, bk in enumerate(b))
    q = 1.0 - phi
    return 8.0 * math.log(q) / phi + s / q**3


@pytest.fixture
def spheres():
    return hardbody.Simulation(sphere_config())


def test_sphere_system_from_dict(spheres):
    assert spheres.N == 500
    assert spheres.time == 0.0
    assert spheres.collisions == 0
    L = spheres.box
    assert L.shape == (3,)
    assert spheres.packing_fraction == pytest.approx(0.3, rel=1e-12)
    assert L.prod() == pytest.approx(500 * math.pi / 6 / 0.3, rel=1e-12)
    assert spheres.temperature == pytest.approx(1.0, rel=1e-12)
    assert spheres.overlaps() == 0


def test_runs_exactly_to_the_time(spheres):
    spheres.run(time=1.25)
    assert spheres.time == 1.25
    assert spheres.collisions > 0
    spheres.run(until=2.0)
    assert spheres.time == 2.0
    spheres.run(time=0.5, collisions=10**9)  # the time limit comes first
    assert spheres.time == 2.5


def test_collisions_increase(spheres):
    spheres.run(time=0.5)
    c0 = spheres.collisions
    spheres.run(time=0.5)
    c1 = spheres.collisions
    assert c1 > c0
    t1 = spheres.time
    spheres.run(collisions=100)
    assert spheres.collisions == c1 + 100
    assert spheres.time > t1
    assert spheres.events["collision"] == spheres.collisions


def test_energy_is_conserved(spheres):
    e0 = spheres.kinetic_energy()
    assert e0 == pytest.approx(1.5 * 500, rel=1e-12)  # kT = 1, translation only
    spheres.run(time=5.0)
    assert spheres.collisions > 10000
    assert abs(spheres.kinetic_energy() / e0 - 1.0) < 1e-10


def test_state_arrays(spheres):
    spheres.run(time=3.0)
    n, L = spheres.N, spheres.box
    r = spheres.positions
    assert r.shape == (n, 3) and r.dtype == np.float64
    assert np.all(r >= 0.0) and np.all(r < L)
    u = spheres.unwrapped_positions
    assert u.shape == (n, 3)
    images = (u - r) / L
    assert np.allclose(images, np.round(images), atol=1e-9)
    assert np.any(np.round(images) != 0)  # in 3 time units some spheres cross the boundary
    v = spheres.velocities
    assert v.shape == (n, 3)
    assert np.allclose(v.sum(axis=0), 0.0, atol=1e-9)  # momentum stays zero
    assert 0.5 * (v**2).sum() == pytest.approx(spheres.kinetic_energy(), rel=1e-12)
    q = spheres.orientations
    assert q.shape == (n, 4)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0)
    assert spheres.angular_velocities.shape == (n, 3)
    # positions are synchronised: every pair is at least a diameter apart now
    d = r[:, None, :] - r[None, :, :]
    d -= L * np.round(d / L)
    dist = np.sqrt((d**2).sum(axis=-1)) + np.eye(n) * 10
    assert dist.min() >= 1.0 - 1e-9
    assert spheres.overlaps() == 0


def test_unwrapped_positions_follow_the_velocities():
    # Free flight of a dilute gas over a time much shorter than the mean free time.
    sim = hardbody.Simulation(sphere_config(n=108, phi=0.01, seed=3))
    u0, v0 = sim.unwrapped_positions, sim.velocities
    sim.run(time=0.01)
    moved = np.all(sim.velocities == v0, axis=1)  # bodies that did not collide
    assert moved.sum() > 100
    assert np.allclose(sim.unwrapped_positions[moved], (u0 + 0.01 * v0)[moved], atol=1e-12)


def test_pressure_matches_hansen_goos():
    sim = hardbody.Simulation(sphere_config(seed=11, output={"log_interval": 0.2}))
    sim.run(time=5.0)  # melt the lattice
    sim.reset_observables()
    sim.run(time=40.0)
    z, err = sim.pressure()
    zref = z_hansen_goos(0.3)
    assert 0.0 < err < 0.01 * zref  # 200 blocks: a meaningful error bar
    assert abs(z - zref) < 4.0 * err, (z, err, zref)


def test_pressure_before_and_after_reset(spheres):
    z, err = spheres.pressure()
    assert math.isnan(z) and math.isnan(err)  # nothing run yet
    spheres.run(time=1.5)
    z2, err2 = spheres.pressure()
    assert z2 > 1.0
    assert math.isnan(err2)  # one closed block (log_interval 1.0) only: no error bar
    spheres.run(time=1.5)
    assert spheres.pressure()[1] > 0.0
    spheres.reset_observables()
    assert math.isnan(spheres.pressure()[0])


def test_same_seed_same_trajectory():
    a = hardbody.Simulation(sphere_config(n=256, seed=5))
    b = hardbody.Simulation(sphere_config(n=256, seed=5))
    a.run(time=1.0)
    b.run(time=1.0)
    assert a.collisions == b.collisions
    assert np.array_equal(a.positions, b.positions)


def test_nnl_spheres():
    sim = hardbody.Simulation(sphere_config(n=256, neighbors={"method": "nnl", "shell": 0.2}))
    sim.run(time=1.0)
    assert sim.collisions > 0 and sim.overlaps() == 0
    assert sim.events["nnl_rebuild"] > 0


@pytest.mark.parametrize("method", ["nnl", "cells"])
def test_ellipsoids_run_without_overlaps(method):
    cfg = {
        "system": {"particles": 128, "packing_fraction": 0.3, "seed": 5},
        "shape": {"type": "ellipsoid", "semi_axes": np.array([1.0, 0.5, 0.5])},
        "neighbors": {"method": method},
    }
    sim = hardbody.Simulation(cfg)
    e0 = sim.kinetic_energy()
    w0 = sim.angular_velocities
    assert np.abs(w0).max() > 0.0
    sim.run(time=0.5)
    assert sim.collisions > 100
    assert sim.overlaps() == 0
    assert sim.min_distance() >= 0.0
    assert abs(sim.kinetic_energy() / e0 - 1.0) < 1e-9
    q = sim.orientations
    assert q.shape == (128, 4)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0)
    assert not np.allclose(q, [1.0, 0.0, 0.0, 0.0])  # the bodies have turned
    assert np.all(sim.positions < sim.box) and np.all(sim.positions >= 0.0)


def test_config_from_toml_file_and_text(tmp_path):
    text = (
        '[system]\nparticles = 108\npacking_fraction = 0.2\nseed = 4\n'
        '[shape]\ntype = "sphere"\nradius = 0.5\n[run]\ntime = 1.0\n'
    )
    path = tmp_path / "c.toml"
    path.write_text(text)
    a = hardbody.Simulation(path)
    b = hardbody.Simulation(str(path), overrides=["system.packing_fraction=0.25"])
    c = hardbody.Simulation.from_toml(text)
    assert a.packing_fraction == pytest.approx(0.2)
    assert b.packing_fraction == pytest.approx(0.25)
    assert np.array_equal(a.velocities, c.velocities)
    assert "packing_fraction = 0.2" in a.config


@pytest.mark.parametrize(
    "change, key",
    [
        ({"system": {"particles": 500, "packing_fraction": -0.3}}, "system.packing_fraction"),
        ({"system": {"particles": 0.5, "packing_fraction": 0.3}}, "system.particles"),
        ({"system": {"particles": 500, "packing_fraction": 0.3, "colour": 1}}, "system.colour"),
        ({"shape": {"type": "sphere", "radius": 0.0}}, "shape.radius"),
        ({"shape": {"type": "cube"}}, "shape.type"),
        ({"shape": {"type": "ellipsoid", "semi_axes": [1, 1]}}, "shape.semi_axes"),
        ({"neighbors": {"method": "octree"}}, "neighbors.method"),
        ({"system": {"particles": 8, "packing_fraction": 0.3}}, "system.packing_fraction"),
    ],
)
def test_bad_config_raises_value_error_naming_the_key(change, key):
    cfg = sphere_config()
    cfg.update(change)
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        hardbody.Simulation(cfg)


def test_other_bad_input():
    with pytest.raises(ValueError, match="nonexistent.toml"):
        hardbody.Simulation("/nonexistent.toml")
    with pytest.raises(TypeError):
        hardbody.Simulation(42)
    with pytest.raises(ValueError, match="system.seed"):
        hardbody.Simulation(sphere_config(seed=object()))
    sim = hardbody.Simulation(sphere_config(n=108))
    with pytest.raises(ValueError):
        sim.run()
    with pytest.raises(ValueError):
        sim.run(time=-1.0)
    with pytest.raises(ValueError):
        sim.run(time=math.inf)
    sim.run(time=1.0)
    with pytest.raises(ValueError):
        sim.run(until=0.5)
    assert sim.time == 1.0


def test_from_gsd_continues_from_a_trajectory_frame(tmp_path):
    import subprocess
    import os
    hb_bin = Path(__file__).resolve().parents[2] / "build" / "apps" / "hardbody" / "hardbody"
    cfg = {"system": {"particles": 108, "packing_fraction": 0.3, "seed": 5},
           "shape": {"type": "sphere", "radius": 0.5},
           "run": {"equilibrate_time": 0.0, "time": 2.0},
           "output": {"log_interval": 0.5, "snapshot_interval": 1.0}}
    toml = tmp_path / "c.toml"
    toml.write_text("\n".join(
        [f"[{sec}]\n" + "\n".join(f"{k} = {json.dumps(v)}" for k, v in kv.items()) for sec, kv in cfg.items()]))
    # a trajectory written by `hardbody run`
    exe = os.environ.get("HARDBODY") or (str(hb_bin) if hb_bin.exists() else None)
    if exe is None:
        pytest.skip("hardbody binary not found")
    r = subprocess.run([exe, "run", str(toml), "--out", str(tmp_path / "o"), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    sim = hardbody.Simulation.from_gsd(str(tmp_path / "o" / "trajectory.gsd"), cfg, frame=-1)
    import gsd.hoomd
    with gsd.hoomd.open(str(tmp_path / "o" / "trajectory.gsd"), mode="rb") as t:
        exact = np.asarray(t[-1].log["particles/hardbody/position_double"])
    assert sim.N == 108 and sim.time == 0.0
    assert np.array_equal(sim.positions, exact)
    e0 = sim.kinetic_energy()
    sim.run(time=1.0)
    assert sim.collisions > 0 and sim.overlaps() == 0
    assert abs(sim.kinetic_energy() / e0 - 1.0) < 1e-12
    with pytest.raises(ValueError, match="system.particles"):
        hardbody.Simulation.from_gsd(str(tmp_path / "o" / "trajectory.gsd"),
                                     dict(cfg, system=dict(cfg["system"], particles=100)))
    with pytest.raises(ValueError):
        hardbody.Simulation.from_gsd(str(tmp_path / "nothing.gsd"), cfg)
    # the frame's species (typeid) must be the config's, count for count
    mix = {"system": {"packing_fraction": 0.3, "seed": 5},
           "species": [{"name": "A", "count": 54, "shape": {"type": "sphere", "radius": 0.5}},
                       {"name": "B", "count": 54, "shape": {"type": "sphere", "radius": 0.5}}]}
    with pytest.raises(ValueError, match="species 'A' given, the config has 54"):
        hardbody.Simulation.from_gsd(str(tmp_path / "o" / "trajectory.gsd"), mix)


def test_correlations_from_python_ballistic_start():
    # at very low density the bodies fly freely over short lags: MSD = <v^2> t^2 exactly
    cfg = {"system": {"particles": 256, "packing_fraction": 0.001, "seed": 2},
           "shape": {"type": "sphere", "radius": 0.5}}
    sim = hardbody.Simulation(cfg)
    c = hardbody.Correlations(interval=0.05, origin_every=1, max_lag=0.5)
    v2 = float(np.mean(np.sum(sim.velocities ** 2, axis=1)))
    c.sample(sim)
    for _ in range(10):
        sim.run(time=0.05)
        c.sample(sim)
    t, msd = c.times, c.msd
    assert t.shape == msd.shape and len(t) == 11
    ok = ~np.isnan(msd)
    assert sim.collisions == 0  # (seed 2: no collision in 0.5 time units at this density)
    assert np.allclose(msd[ok], v2 * t[ok] ** 2, rtol=1e-9, atol=1e-12)
    assert abs(c.c2[0] - 1.0) < 1e-12 and np.all(c.fself[ok] <= 1.0 + 1e-12)


def test_sphere_mixture_from_dict():
    cfg = {"system": {"packing_fraction": 0.3, "seed": 1},
           "species": [{"name": "A", "count": 100, "shape": {"type": "sphere", "radius": 0.5}},
                       {"name": "B", "count": 100, "mass": 0.5, "shape": {"type": "sphere", "radius": 0.35}}]}
    sim = hardbody.Simulation(cfg)
    assert sim.N == 200 and sim.packing_fraction == pytest.approx(0.3, rel=1e-12)
    e0 = sim.kinetic_energy()
    sim.run(time=1.0)
    assert sim.collisions > 100 and sim.overlaps() == 0
    assert abs(sim.kinetic_energy() / e0 - 1.0) < 1e-12
    with pytest.raises(ValueError, match=r"species\[1\]\.count"):
        hardbody.Simulation(dict(cfg, species=[cfg["species"][0], dict(cfg["species"][1], count=0)]))
    # a sphere first, then an ellipsoid: a mixture of unlike shapes (it once built nothing and
    # crashed), grown and run by the generic rigid-body model
    mix = hardbody.Simulation(dict(cfg, species=[cfg["species"][0], dict(
        cfg["species"][1], shape={"type": "ellipsoid", "semi_axes": [1.0, 0.5, 0.5]})]))
    e0 = mix.kinetic_energy()
    mix.run(time=0.2)
    assert mix.collisions > 10 and mix.overlaps() == 0
    assert abs(mix.kinetic_energy() / e0 - 1.0) < 1e-12
