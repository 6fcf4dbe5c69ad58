"""Contract of `hardbody run`: outputs, summary keys, and exit status 2 with one clear message
for bad input, leaving nothing behind."""
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

HB = os.environ.get("HARDBODY", "hardbody")
EXAMPLES = Path(os.environ.get("HARDBODY_EXAMPLES", "examples"))

GOOD = """
[system]
particles = 256
packing_fraction = 0.3
seed = 3
[shape]
type = "sphere"
radius = 0.5
[run]
equilibrate_time = 0.5
time = 2.0
[output]
log_interval = 0.25
"""

SUMMARY_KEYS = ["particles", "packing_fraction", "box", "shape", "time", "collisions",
                "wall_seconds", "cpu_seconds", "collisions_per_second", "tau_c_us", "Z",
                "Z_error", "collision_rate", "temperature", "energy_drift", "overlaps",
                "min_distance", "events", "solver_fallbacks"]


def run(args, cwd):
    return subprocess.run([HB, *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_run_writes_contract_outputs(tmp_path):
    cfg = tmp_path / "small.toml"
    cfg.write_text(GOOD)
    r = run(["run", str(cfg)], tmp_path)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "run-small"
    for name in ["config.resolved.toml", "log.tsv", "summary.json"]:
        assert (out / name).is_file(), name
    assert not list(out.glob("*.tmp")) and not list(out.glob("*.part"))
    s = json.loads((out / "summary.json").read_text())
    for k in SUMMARY_KEYS:
        assert k in s, k
    assert s["particles"] == 256 and s["overlaps"] == 0 and s["collisions"] > 0
    assert s["cpu_seconds"] > 0 and s["tau_c_us"] > 0 and s["collisions_per_second"] > 0
    assert abs(s["time"] - 2.0) < 1e-9
    rows = (out / "log.tsv").read_text().strip().splitlines()
    assert rows[0].startswith("time\t") and len(rows) == 1 + 8
    # the resolved config runs again as is
    r2 = run(["run", str(out / "config.resolved.toml"), "--out", str(tmp_path / "again")], tmp_path)
    assert r2.returncode == 0, r2.stderr
    s2 = json.loads((tmp_path / "again" / "summary.json").read_text())
    assert s2["collisions"] == s["collisions"] and s2["Z"] == s["Z"]  # same seed, same run


def test_set_override_and_out(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(GOOD)
    r = run(["run", str(cfg), "--out", "o", "--set", "system.particles=108", "--set", "run.time=1"], tmp_path)
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["particles"] == 108


SUPERQUADRIC = """
[system]
particles = 108
packing_fraction = 0.2
seed = 4
[shape]
type = "superquadric"
semi_axes = [1.0, 0.5, 0.5]
exponents = [4.0, 4.0, 4.0]
[init]
method = "lattice"
[run]
equilibrate_time = 0.2
time = {time}
[neighbors]
method = "{method}"
[output]
log_interval = 0.25
snapshot_interval = 0.5
checkpoint_interval = 0.05
"""


BAD = [
    ("missing file", None, "cannot open config file"),
    ("malformed", GOOD.replace("seed = 3", "seed = = 3"), "malformed TOML"),
    ("unknown key", GOOD.replace("seed = 3", "colour = 3"), "unknown key 'system.colour'"),
    ("wrong type", GOOD.replace("particles = 256", "particles = \"256\""), "system.particles"),
    ("negative radius", GOOD.replace("radius = 0.5", "radius = -1.0"), "shape.radius"),
    ("zero radius", GOOD.replace("radius = 0.5", "radius = 0"), "shape.radius"),
    ("phi >= 0.74", GOOD.replace("packing_fraction = 0.3", "packing_fraction = 0.75"), "system.packing_fraction"),
    ("N = 0", GOOD.replace("particles = 256", "particles = 0"), "system.particles"),
    ("too dense for lattice", GOOD.replace("particles = 256", "particles = 250").replace("0.3", "0.73"), "system.packing_fraction"),
    ("box too small", GOOD.replace("particles = 256", "particles = 2"), "system.particles"),
]
SQ = SUPERQUADRIC.format(method="nnl", time=1.0)
BAD += [
    ("superquadric exponent below 2", SQ.replace("[4.0, 4.0, 4.0]", "[4.0, 1.5, 4.0]"), "shape.exponents"),
    ("superquadric without exponents", SQ.replace("exponents = [4.0, 4.0, 4.0]\n", ""), "shape.exponents"),
    ("superquadric too dense for lattice", SQ.replace("packing_fraction = 0.2", "packing_fraction = 0.7"),
     "system.packing_fraction"),
    ("superquadric box too small", SQ.replace("particles = 108", "particles = 4"), "system.particles"),
]


@pytest.mark.parametrize("name,text,expect", BAD, ids=[b[0] for b in BAD])
def test_bad_input_exits_2_and_writes_nothing(tmp_path, name, text, expect):
    cfg = tmp_path / "bad.toml"
    if text is not None:
        cfg.write_text(text)
    r = run(["run", str(cfg)], tmp_path)
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = [l for l in r.stderr.strip().splitlines() if l]
    assert len(lines) == 1, r.stderr
    assert expect in lines[0], lines[0]
    assert "bad.toml" in lines[0]
    assert not (tmp_path / "run-bad").exists()


def test_unknown_option_exits_2(tmp_path):
    r = run(["run", "--bogus"], tmp_path)
    assert r.returncode == 2


def body(shape, pos, q=(1, 0, 0, 0), v=None, w=None):
    b = {"shape": shape, "position": list(pos), "orientation": list(q)}
    if v is not None:
        b["velocity"] = list(v)
        b["angular_velocity"] = list(w)
    return b


def query(cmd, lines, tmp_path):
    r = subprocess.run([HB, cmd], input="\n".join(json.dumps(l) for l in lines) + "\n",
                       capture_output=True, text=True, timeout=60, cwd=tmp_path)
    return r, [json.loads(l) for l in r.stdout.strip().splitlines()]


def test_distance_contract(tmp_path):
    sph = {"type": "sphere", "radius": 0.5}
    ell = {"type": "ellipsoid", "semi_axes": [2.0, 1.0, 0.5]}
    c, s = 2 ** -0.5, 2 ** -0.5  # 90 degrees about z
    pairs = [
        {"a": body(sph, (0, 0, 0)), "b": body(sph, (3, 4, 0))},
        {"a": body(ell, (0, 0, 0)), "b": body(sph, (0, 3, 0))},
        {"a": body(ell, (0, 0, 0), (c, 0, 0, s)), "b": body(ell, (4.5, 0, 0))},
        {"a": body(ell, (0, 0, 0)), "b": body(ell, (3.9, 0, 0))},  # overlapping: negative
    ]
    r, out = query("distance", pairs, tmp_path)
    assert r.returncode == 0, r.stderr
    assert abs(out[0]["distance"] - 4.0) < 1e-12
    assert abs(out[1]["distance"] - 1.5) < 1e-9
    assert abs(out[2]["distance"] - 1.5) < 1e-9  # a rotated: extent 1 along x; b extends 2 towards a
    assert out[3]["distance"] < 0
    for o in out:
        assert len(o["point_a"]) == 3 and len(o["point_b"]) == 3
    # symmetric in a and b
    r2, back = query("distance", [{"a": p["b"], "b": p["a"]} for p in pairs], tmp_path)
    for o, p in zip(out, back):
        assert abs(o["distance"] - p["distance"]) < 1e-9


def test_contact_time_contract(tmp_path):
    sph = {"type": "sphere", "radius": 0.5}
    pairs = [
        {"a": body(sph, (0, 0, 0), v=(1, 0, 0), w=(0, 0, 0)),
         "b": body(sph, (3, 0, 0), v=(-1, 0, 0), w=(0, 0, 0)), "t_max": 10},
        {"a": body(sph, (0, 0, 0), v=(1, 0, 0), w=(0, 0, 0)),
         "b": body(sph, (3, 0, 0), v=(2, 0, 0), w=(0, 0, 0)), "t_max": 10},
        {"a": body(sph, (0, 0, 0), v=(1, 0, 0), w=(0, 0, 0)),
         "b": body(sph, (3, 0, 0), v=(-1, 0, 0), w=(0, 0, 0)), "t_max": 0.5},
    ]
    r, out = query("contact-time", pairs, tmp_path)
    assert r.returncode == 0, r.stderr
    assert abs(out[0]["time"] - 1.0) < 1e-9
    assert abs(out[0]["normal"][0] - 1.0) < 1e-9 and abs(out[0]["point"][0] - 1.5) < 1e-6
    assert out[1]["time"] is None and out[2]["time"] is None


@pytest.mark.parametrize("line,expect", [
    ("not json", "malformed JSON"),
    ('{"a": {}}', "a"),
    ('{"a": {"shape": {"type": "cube"}, "position": [0,0,0], "orientation": [1,0,0,0]}, "b": {}}', "unknown shape type 'cube'"),
    ('{"a": {"shape": {"type": "sphere", "radius": -1}, "position": [0,0,0], "orientation": [1,0,0,0]}, "b": {}}', "shape: key 'radius': must be positive"),
])
def test_pair_queries_bad_input_exit_2(tmp_path, line, expect):
    r = subprocess.run([HB, "distance"], input=line + "\n", capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2 and "<stdin>:1" in r.stderr and expect in r.stderr, r.stderr


def test_superquadric_pair_queries(tmp_path):
    sq = {"type": "superquadric", "semi_axes": [1.0, 0.5, 0.5], "exponents": [8, 8, 8]}
    sph = {"type": "sphere", "radius": 0.5}
    r, out = query("distance", [{"a": body(sq, (0, 0, 0)), "b": body(sph, (3, 0, 0))}], tmp_path)
    assert r.returncode == 0, r.stderr
    assert abs(out[0]["distance"] - 1.5) < 1e-9
    r, out = query("contact-time", [{"a": body(sq, (0, 0, 0), v=(0, 0, 0), w=(0, 0, 0)),
                                     "b": body(sph, (3, 0, 0), v=(-0.5, 0, 0), w=(0, 0, 0)),
                                     "t_max": 10}], tmp_path)
    assert r.returncode == 0, r.stderr
    assert abs(out[0]["time"] - 3.0) < 1e-8


@pytest.mark.parametrize("method", ["nnl", "cells"])
def test_run_accepts_superquadrics(tmp_path, method):
    cfg = tmp_path / "sq.toml"
    cfg.write_text(SUPERQUADRIC.format(method=method, time=1.0))
    r = run(["run", str(cfg), "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "run-sq"
    s = json.loads((out / "summary.json").read_text())
    for k in SUMMARY_KEYS:
        assert k in s, k
    assert s["shape"] == {"type": "superquadric", "semi_axes": [1.0, 0.5, 0.5],
                          "exponents": [4.0, 4.0, 4.0]}
    assert s["neighbors"] == method and s["collisions"] > 100
    assert s["overlaps"] == 0 and s["snapshot_overlaps"] == 0 and s["min_distance"] > 0
    assert abs(s["energy_drift"]) < 1e-10
    assert "exponents = [ 4.0, 4.0, 4.0 ]" in (out / "config.resolved.toml").read_text()
    # the trajectory draws the body as a convex polyhedron of surface points
    gsd_hoomd = pytest.importorskip("gsd.hoomd")
    with gsd_hoomd.open(str(out / "trajectory.gsd"), mode="rb") as t:
        assert len(t) == s["trajectory_frames"] >= 2
        shape = t[0].particles.type_shapes[0]
        assert t[0].particles.types == ["superquadric"]
    assert shape["type"] == "ConvexPolyhedron" and 200 <= len(shape["vertices"]) <= 1000
    for x, y, z in shape["vertices"]:
        assert abs(abs(x / 1.0) ** 4 + abs(y / 0.5) ** 4 + abs(z / 0.5) ** 4 - 1.0) < 1e-9


def assert_resume_reproduces(tmp_path, cfg_text, delay, keys):
    """Run to the end; run again, SIGTERM after `delay` s, --resume: same summary keys and log."""
    import signal
    import time

    cfg = tmp_path / "c.toml"
    cfg.write_text(cfg_text)
    full = run(["run", str(cfg), "--out", "full", "--quiet"], tmp_path)
    assert full.returncode == 0, full.stderr
    p = subprocess.Popen([HB, "run", str(cfg), "--out", "part", "--quiet"], cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=300)
    if p.returncode == 0:
        pytest.skip("the run finished before the signal")
    assert p.returncode == 128 + signal.SIGTERM, (p.returncode, err)
    res = run(["run", str(cfg), "--out", "part", "--resume", "--quiet"], tmp_path)
    assert res.returncode == 0, res.stderr
    a = json.loads((tmp_path / "full" / "summary.json").read_text())
    b = json.loads((tmp_path / "part" / "summary.json").read_text())
    for k in keys:
        assert a[k] == b[k], k
    assert (tmp_path / "full" / "log.tsv").read_text() == (tmp_path / "part" / "log.tsv").read_text()


def test_superquadric_resume_reproduces_uninterrupted_run(tmp_path):
    assert_resume_reproduces(tmp_path, SUPERQUADRIC.format(method="nnl", time=4.0), 0.8,
                             ["collisions", "Z", "energy_drift", "overlaps", "min_distance",
                              "packing_fraction"])



MIXTURE = """
[system]
packing_fraction = 0.35
seed = 4
[[species]]
name = "big"
count = 300
shape = {{ type = "sphere", radius = 0.5 }}
polydispersity = {{ distribution = "uniform", width = 0.05 }}
[[species]]
name = "small"
count = 600
mass = 0.5
shape = {{ type = "sphere", radius = 0.3 }}
[run]
equilibrate_time = 1.0
time = {time}
[output]
log_interval = 0.5
snapshot_interval = 1.0
checkpoint_interval = 0.2
"""


def test_mixture_outputs_name_the_species(tmp_path):
    cfg = tmp_path / "mix.toml"
    cfg.write_text(MIXTURE.format(time=2.0))
    r = run(["run", str(cfg), "--out", "o", "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    for k in SUMMARY_KEYS:
        assert k in s, k
    assert s["particles"] == 900 and s["overlaps"] == 0 and abs(s["energy_drift"]) < 1e-12
    assert [x["name"] for x in s["species"]] == ["big", "small"]
    for x in s["species"]:
        for k in ["name", "count", "mass", "inertia", "temperature_translational",
                  "temperature_rotational", "temperature_rotational_axes"]:
            assert k in x, k
    assert s["species"][1]["mass"] == 0.5 and s["species"][1]["count"] == 600
    assert {(p["a"], p["b"]) for p in s["species_pairs"]} == {
        ("big", "big"), ("big", "small"), ("small", "big"), ("small", "small")}
    assert s["init"]["method"] == "grow"
    for name in ["big", "small"]:  # MSD, C2, F_self per species
        assert (tmp_path / "o" / f"correlations_{name}.tsv").read_text().count("\n") > 5
    gp = (tmp_path / "o" / "gr_partial.tsv").read_text().splitlines()
    assert "r\tg_big_big\tg_big_small\tg_small_small" in gp
    r = run(["plot", "o"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "o" / "gr_partial.png").is_file()
    resolved = (tmp_path / "o" / "config.resolved.toml").read_text()
    assert "[[species]]" in resolved and "name = 'small'" in resolved and "inertia" in resolved
    gsd_hoomd = pytest.importorskip("gsd.hoomd")
    with gsd_hoomd.open(str(tmp_path / "o" / "trajectory.gsd"), mode="rb") as t:
        f = t[-1]
        assert f.particles.types == ["big", "small"]
        assert list(np.bincount(f.particles.typeid)) == [300, 600]
        assert f.particles.type_shapes == [{"type": "Sphere", "diameter": 1.0},
                                           {"type": "Sphere", "diameter": 0.6}]
        d = np.asarray(f.particles.diameter)
        scale = np.asarray(f.log["particles/hardbody/scale"])
        assert np.allclose(d[:300], scale[:300], rtol=1e-6) and np.std(scale[:300]) > 0.03
        assert np.allclose(d[300:], 0.6, rtol=1e-6)


def test_mixture_resume_reproduces_uninterrupted_run(tmp_path):
    assert_resume_reproduces(tmp_path, MIXTURE.format(time=30.0), 0.6,
                             ["collisions", "Z", "energy_drift", "overlaps", "min_distance",
                              "packing_fraction", "species", "species_pairs"])


RIGID_MIXTURE = """
[system]
packing_fraction = 0.3
seed = 6
[[species]]
name = "S"
count = 100
shape = {{ type = "sphere", radius = 0.45 }}
[[species]]
name = "E"
count = 100
shape = {{ type = "ellipsoid", semi_axes = [1.0, 0.5, 0.4] }}
polydispersity = {{ distribution = "gaussian", width = 0.08 }}
[neighbors]
method = "{method}"
[run]
equilibrate_time = 0.5
time = {time}
[output]
log_interval = 0.5
snapshot_interval = 1.0
checkpoint_interval = 0.2
"""


@pytest.mark.parametrize("method", ["cells", "nnl"])
def test_rigid_mixture_resume_reproduces_uninterrupted_run(tmp_path, method):
    """A polydisperse sphere-ellipsoid mixture (asymmetric tops) with either neighbour method."""
    assert_resume_reproduces(tmp_path, RIGID_MIXTURE.format(method=method, time=6.0), 1.5,
                             ["collisions", "Z", "energy_drift", "overlaps", "min_distance",
                              "packing_fraction", "species", "neighbors"])
