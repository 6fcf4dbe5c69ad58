"""Issue 13, pair queries: `hardbody distance` / `hardbody contact-time` regressions. Unknown keys,
overflowing numbers, directories and non-physical inputs exit 2 with one message naming the
line and key; overlapping pairs report the true penetration depth; tiny quaternions, t_max = 0
and pairs of size 1e200 or 1e-200 give the answers of the plain case."""
import json
import math
import os
import subprocess

import pytest

from test_cli import body  # (shape, pos, q, v, w) -> a BODY of the JSON-lines format

HB = os.environ.get("HARDBODY", "hardbody")


def call(cmd, text, *args, cwd=None):
    return subprocess.run([HB, cmd, *args], input=text, capture_output=True, text=True,
                          timeout=60, cwd=cwd)


def one(cmd, pair, *args):
    r = call(cmd, json.dumps(pair) + "\n", *args)
    assert r.returncode == 0, r.stderr
    (line,) = r.stdout.strip().splitlines()
    return json.loads(line)


def refused(cmd, text, *args):
    r = call(cmd, text, *args)
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    assert r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hardbody: error: "), r.stderr
    return lines[0]


SPH = {"type": "sphere", "radius": 1.0}
ELL = {"type": "ellipsoid", "semi_axes": [2.0, 1.0, 1.0]}


# ---- 1. unknown keys ---------------------------------------------------------------------------
@pytest.mark.parametrize("where,mutate,expect", [
    ("top", lambda p: p.update(extra=1), "'extra'"),
    ("top typo", lambda p: p.update(t_mx=1), "'t_mx' (did you mean 't_max'?)"),
    ("body", lambda p: p["a"].update(colour="red"), "'a.colour'"),
    ("body typo", lambda p: p["b"].update(positon=[0, 0, 0]), "'b.positon' (did you mean 'position'?)"),
    ("shape", lambda p: p["a"]["shape"].update(Radius=2), "'a.shape.Radius' (did you mean 'radius'?)"),
    ("shape other type", lambda p: p["b"]["shape"].update(exponents=[2, 2, 2]), "'b.shape.exponents'"),
])
def test_unknown_keys_exit_2_naming_the_key(where, mutate, expect):
    pair = {"a": body(dict(SPH), (0, 0, 0)), "b": body(dict(ELL), (4, 0, 0))}
    mutate(pair)
    msg = refused("distance", json.dumps(pair) + "\n")
    assert "<stdin>:1: unknown key" in msg and expect in msg, msg


def test_all_unknown_keys_in_one_message():
    pair = {"a": body(dict(SPH, radus=1), (0, 0, 0)), "b": body(dict(ELL), (4, 0, 0)), "x": 0}
    pair["b"]["orientaton"] = [1, 0, 0, 0]
    msg = refused("contact-time", "\n" + json.dumps(pair) + "\n")
    assert "<stdin>:2: unknown keys" in msg
    for k in ["'x'", "'b.orientaton' (did you mean 'orientation'?)", "'a.shape.radus' (did you mean 'radius'?)"]:
        assert k in msg, msg


def test_contact_time_keys_are_known_to_distance():
    # a contact-time line (a run's reproducer) can be given to `hardbody distance`
    pair = {"a": body(SPH, (0, 0, 0), v=(1, 0, 0), w=(0, 0, 1)),
            "b": body(SPH, (3, 0, 0), v=(0, 0, 0), w=(0, 0, 0)), "t_max": 1}
    pair["b"]["inertia"] = [1, 2, 3]
    assert one("distance", pair)["distance"] == pytest.approx(1.0, abs=1e-12)


# ---- 2. penetration depth ----------------------------------------------------------------------
NEEDLE = {"type": "ellipsoid", "semi_axes": [1000.0, 1.0, 1.0]}
QZ90 = (math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4))


@pytest.mark.parametrize("pair,depth", [
    # crossing needles of aspect 1000: the shortest separating translation is 2, along z (was -1001)
    ({"a": body(NEEDLE, (0, 0, 0)), "b": body(NEEDLE, (0, 0, 0), QZ90)}, 2.0),
    ({"a": body(NEEDLE, (0, 0, 0)), "b": body(NEEDLE, (0, 0, 0.5), QZ90)}, 1.5),
    # coincident (2, 1, 1) ellipsoids: separated by moving 2 along a minor axis (was -4)
    ({"a": body(ELL, (1, 2, 3)), "b": body(ELL, (1, 2, 3))}, 2.0),
    ({"a": body(ELL, (0, 0, 0), QZ90), "b": body(ELL, (0, 0, 0), QZ90)}, 2.0),
])
def test_overlapping_pairs_report_the_penetration_depth(pair, depth):
    for p in (pair, {"a": pair["b"], "b": pair["a"]}):
        r = call("distance", json.dumps(p) + "\n")
        assert r.returncode == 0 and r.stderr == "", r.stderr
        o = json.loads(r.stdout)
        assert o["distance"] == pytest.approx(-depth, abs=1e-9)
        gap = [b - a for a, b in zip(o["point_a"], o["point_b"])]
        assert math.sqrt(sum(g * g for g in gap)) == pytest.approx(depth, abs=1e-9)


# ---- 3. quaternions ----------------------------------------------------------------------------
def test_tiny_quaternions_are_normalised_without_loss():
    ref = {"a": body(ELL, (0, 0, 0), (1, 0, 0, 1)), "b": body(ELL, (2.5, 1, 0), (1, 1, 0, 0))}
    want = one("distance", ref)
    for s in (1e-160, 1e-170, 1e-300, 1e300):
        p = {"a": body(ELL, (0, 0, 0), (s, 0, 0, s)), "b": body(ELL, (2.5, 1, 0), (s, s, 0, 0))}
        assert one("distance", p) == want, s
    msg = refused("distance", json.dumps({"a": body(ELL, (0, 0, 0), (0, 0, 0, 0)),
                                          "b": body(ELL, (3, 0, 0))}) + "\n")
    assert "'a.orientation'" in msg and "non-zero" in msg


# ---- 4. t_max = 0 ------------------------------------------------------------------------------
def test_t_max_zero_on_a_touching_approaching_pair_is_a_contact_at_0():
    def pair(vb, x=2.0):
        return {"a": body(SPH, (0, 0, 0), v=(0, 0, 0), w=(0, 0, 0)),
                "b": body(SPH, (x, 0, 0), v=vb, w=(0, 0, 0)), "t_max": 0}
    o = one("contact-time", pair((-1, 0, 0)))
    assert o["time"] == 0.0 and o["normal"] == [1.0, 0.0, 0.0] and o["point"] == [1.0, 0.0, 0.0]
    assert one("contact-time", pair((1, 0, 0)))["time"] is None       # separating
    assert one("contact-time", pair((-1, 0, 0), 2.5))["time"] is None  # apart


# ---- 5. numbers that overflow a double ---------------------------------------------------------
@pytest.mark.parametrize("text,key", [
    ('{"a": {"shape": {"type": "sphere", "radius": 1e400}, "position": [0,0,0], "orientation": [1,0,0,0]}, "b": {}}', "a.shape.radius"),
    ('{"a": {"shape": {"type": "sphere", "radius": 1}, "position": [0,-1e400,0], "orientation": [1,0,0,0]}, "b": {}}', "a.position"),
    ('{"t_max": 1e999, "a": {}}', "t_max"),
])
def test_overflowing_numbers_exit_2_naming_the_key(text, key):
    for cmd in ("distance", "contact-time"):
        msg = refused(cmd, text + "\n")
        assert f"<stdin>:1: key '{key}'" in msg and "out of the range of a double" in msg, msg
        assert "json.exception" not in msg


# ---- 6. a directory as input -------------------------------------------------------------------
def test_directory_input_exits_2(tmp_path):
    for cmd in ("distance", "contact-time"):
        r = subprocess.run([HB, cmd, str(tmp_path)], capture_output=True, text=True, timeout=60)
        assert r.returncode == 2 and "is a directory" in r.stderr and r.stdout == "", r.stderr


# ---- 7. scale invariance and non-physical inputs -----------------------------------------------
def scaled(s, moving=False):
    sq = {"type": "superquadric", "semi_axes": [s, s, s], "exponents": [4, 4, 4]}
    el = {"type": "ellipsoid", "semi_axes": [2 * s, s, 0.5 * s]}
    if not moving:
        return {"a": body(el, (0, 0, 0), (1, 0.1, 0.2, 0)), "b": body(sq, (4 * s, 0.5 * s, 0), (1, 0, 0, 0.3))}
    return {"a": body(el, (0, 0, 0), (1, 0.1, 0.2, 0), v=(s, 0, 0), w=(0, 0, 0.3)),
            "b": body(sq, (6 * s, 0.5 * s, 0), (1, 0, 0, 0.3), v=(-s, 0, 0), w=(0.2, 0, 0)), "t_max": 10}


@pytest.mark.parametrize("s", [1e200, 1e-200, 2.0 ** 1000, 2.0 ** -1000])
def test_scaled_copies_give_scaled_answers(s):
    base, big = one("distance", scaled(1.0)), one("distance", scaled(s))
    assert big["distance"] == pytest.approx(s * base["distance"], rel=1e-14)
    for k in ("point_a", "point_b"):
        assert big[k] == pytest.approx([s * x for x in base[k]], rel=1e-13, abs=1e-14 * s)
    # overlapping copies too (the penetration path)
    pen = scaled(1.0)
    pen["b"]["position"] = [2.2, 0.5, 0]
    pen_s = scaled(s)
    pen_s["b"]["position"] = [2.2 * s, 0.5 * s, 0]
    assert one("distance", pen_s)["distance"] == pytest.approx(s * one("distance", pen)["distance"], rel=1e-13)
    # contact times are invariant when velocities and eps_d scale with the lengths
    t0 = one("contact-time", scaled(1.0, True))
    ts = one("contact-time", scaled(s, True), "--eps-d", repr(1e-5 * s))
    assert ts["time"] == pytest.approx(t0["time"], rel=1e-12)
    assert ts["normal"] == pytest.approx(t0["normal"], abs=1e-12)


@pytest.mark.parametrize("args,mutate,expect", [
    (["--eps-d", "1e200"], None, "--eps-d 1e+200 is not small against the bodies"),
    (["--eps-d", "1e-20"], None, "--eps-d 1e-20 is below the rounding"),
    ([], lambda p: p["b"].update(angular_velocity=[0, 0, 1e300]), "key 'b.angular_velocity': |w| = 1e+300"),
    ([], lambda p: p["a"].update(angular_velocity=[1e15, 0, 0]), "key 'a.angular_velocity'"),
    ([], lambda p: p.update(t_max=-1), "key 't_max' must not be negative"),
])
def test_non_physical_contact_queries_exit_2(args, mutate, expect):
    pair = scaled(1.0, True)
    if mutate:
        mutate(pair)
    msg = refused("contact-time", json.dumps(pair) + "\n", *args)
    assert expect in msg, msg
    assert len(msg) < 400 and "0000000000" not in msg, msg  # no 309-digit numbers


@pytest.mark.parametrize("value", ["-1", "0", "nan", "inf", "1e400"])
def test_eps_d_out_of_range_message_is_short(value):
    r = call("contact-time", json.dumps(scaled(1.0, True)) + "\n", "--eps-d", value)
    assert r.returncode == 2, r.stderr
    assert "--eps-d" in r.stderr and len(r.stderr) < 200, r.stderr


@pytest.mark.parametrize("c", [2.0 ** 900, 2.0 ** -900, 1e100, 3.0])
def test_time_scaled_copies_give_scaled_times(c):
    # speeds times c, angular speeds times c, t_max over c: the contact time over c
    base = scaled(1.0, True)
    fast = json.loads(json.dumps(base))
    for b in ("a", "b"):
        fast[b]["velocity"] = [c * x for x in fast[b]["velocity"]]
        fast[b]["angular_velocity"] = [c * x for x in fast[b]["angular_velocity"]]
    fast["t_max"] = base["t_max"] / c
    t0, tc = one("contact-time", base), one("contact-time", fast)
    assert tc["time"] == pytest.approx(t0["time"] / c, rel=1e-12)
    assert tc["point"] == pytest.approx(t0["point"], rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("shape_a,mutate,expect", [
    (ELL, lambda p: p["b"].update(position=[1e200, 0, 0]), "more than 1e100 times their size"),
    (ELL, lambda p: p["a"]["shape"].update(semi_axes=[2.0, 1e150, 5e299]), "span more than a factor 1e100"),
    (SPH, lambda p: p["a"]["shape"].update(radius=1e-310), "below the smallest normal double"),
])
def test_unresolvable_pairs_exit_2(shape_a, mutate, expect):
    pair = {"a": body(dict(shape_a), (0, 0, 0), v=(0, 0, 0), w=(0, 0, 0)),
            "b": body(dict(ELL), (4, 0, 0), v=(0, 0, 0), w=(0, 0, 0)), "t_max": 1}
    mutate(pair)
    for cmd in ("distance", "contact-time"):
        msg = refused(cmd, json.dumps(pair) + "\n")
        assert "<stdin>:1:" in msg and expect in msg, msg
