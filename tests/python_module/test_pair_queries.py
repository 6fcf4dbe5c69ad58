"""hardbody.distance / hardbody.contact_time: analytic sphere answers, symmetry, errors."""

import math

import numpy as np
import pytest

import hardbody


def body(shape, position, orientation=(1.0, 0.0, 0.0, 0.0), velocity=(0.0, 0.0, 0.0),
         angular_velocity=(0.0, 0.0, 0.0)):
    return {"shape": shape, "position": list(position), "orientation": list(orientation),
            "velocity": list(velocity), "angular_velocity": list(angular_velocity)}


def sphere(r):
    return {"type": "sphere", "radius": r}


def ellipsoid(a, b, c):
    return {"type": "ellipsoid", "semi_axes": [a, b, c]}


def random_unit_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def test_sphere_distance_is_analytic():
    ca, cb = np.array([0.1, -0.2, 0.3]), np.array([1.4, 0.9, -0.6])
    a, b = body(sphere(0.5), ca), body(sphere(0.7), cb, orientation=(0.0, 1.0, 0.0, 0.0))
    d = hardbody.distance(a, b)
    sep = np.linalg.norm(cb - ca)
    assert d["distance"] == pytest.approx(sep - 1.2, abs=1e-10)
    u = (cb - ca) / sep
    assert np.allclose(d["point_a"], ca + 0.5 * u, atol=1e-8)
    assert np.allclose(d["point_b"], cb - 0.7 * u, atol=1e-8)


def test_overlapping_spheres_have_negative_distance():
    d = hardbody.distance(body(sphere(0.5), (0, 0, 0)), body(sphere(0.5), (0.8, 0, 0)))
    assert d["distance"] == pytest.approx(-0.2, abs=1e-10)


def test_ellipsoid_distance_along_the_long_axis():
    # Two (2, 1, 1) ellipsoids end to end along x: gap = 5 - 2 - 2.
    e = ellipsoid(2.0, 1.0, 1.0)
    d = hardbody.distance(body(e, (0, 0, 0)), body(e, (5, 0, 0)))
    assert d["distance"] == pytest.approx(1.0, abs=1e-8)
    # turned by 90 degrees about z, the second one shows its short side: gap = 5 - 2 - 1
    qz = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))
    d = hardbody.distance(body(e, (0, 0, 0)), body(e, (5, 0, 0), orientation=qz))
    assert d["distance"] == pytest.approx(2.0, abs=1e-8)


def test_distance_is_symmetric():
    rng = np.random.default_rng(17)
    for _ in range(20):
        a = body(ellipsoid(1.0, 0.5, 0.3), rng.uniform(-0.2, 0.2, 3), random_unit_quaternion(rng))
        b = body(ellipsoid(0.8, 0.6, 0.4), rng.uniform(1.5, 2.5, 3), random_unit_quaternion(rng))
        ab, ba = hardbody.distance(a, b), hardbody.distance(b, a)
        assert ab["distance"] > 0.0
        assert ab["distance"] == pytest.approx(ba["distance"], abs=1e-8)
        assert np.allclose(ab["point_a"], ba["point_b"], atol=1e-6)
        assert np.allclose(ab["point_b"], ba["point_a"], atol=1e-6)


def test_contact_time_of_approaching_spheres_is_analytic():
    # Head on: gap 2.0 closed at relative speed 1.5.
    a = body(sphere(0.5), (0, 0, 0), velocity=(1.0, 0, 0))
    b = body(sphere(0.5), (3.0, 0, 0), velocity=(-0.5, 0, 0))
    r = hardbody.contact_time(a, b, t_max=10.0)
    assert r["time"] == pytest.approx(2.0 / 1.5, abs=1e-9)
    assert np.allclose(r["normal"], [1.0, 0.0, 0.0], atol=1e-8)
    assert np.allclose(r["point"], [0.5 + 2.0 / 1.5, 0.0, 0.0], atol=1e-7)
    # Oblique: |dr + dv t| = sigma solved in closed form.
    dr, dv, sigma = np.array([3.0, 0.4, -0.3]), np.array([-1.0, 0.1, 0.05]), 1.1
    a = body(sphere(0.6), (0, 0, 0))
    b = body(sphere(0.5), dr, velocity=dv)
    bq, cq = dr @ dv, dr @ dr - sigma**2
    t = (-bq - math.sqrt(bq * bq - (dv @ dv) * cq)) / (dv @ dv)
    assert hardbody.contact_time(a, b, t_max=10.0)["time"] == pytest.approx(t, abs=1e-9)
    # too late for t_max
    assert hardbody.contact_time(a, b, t_max=0.5 * t)["time"] is None


def test_contact_time_is_none_for_separating_spheres():
    a = body(sphere(0.5), (0, 0, 0), velocity=(-1.0, 0, 0))
    b = body(sphere(0.5), (3.0, 0, 0), velocity=(0.5, 0, 0))
    r = hardbody.contact_time(a, b, t_max=100.0)
    assert r == {"time": None, "point": None, "normal": None}


def test_contact_time_is_symmetric_for_ellipsoids():
    rng = np.random.default_rng(4)
    hits = 0
    for _ in range(10):
        a = body(ellipsoid(1.0, 0.5, 0.5), (0, 0, 0), random_unit_quaternion(rng),
                 velocity=(0.5, 0, 0), angular_velocity=rng.normal(size=3))
        b = body(ellipsoid(1.0, 0.5, 0.5), (4.0, rng.uniform(-0.5, 0.5), 0.0),
                 random_unit_quaternion(rng), velocity=(-0.5, 0, 0),
                 angular_velocity=rng.normal(size=3))
        ab = hardbody.contact_time(a, b, t_max=5.0)
        ba = hardbody.contact_time(b, a, t_max=5.0)
        assert (ab["time"] is None) == (ba["time"] is None)
        if ab["time"] is not None:
            hits += 1
            assert ab["time"] == pytest.approx(ba["time"], abs=1e-7)
            assert np.allclose(ab["point"], ba["point"], atol=1e-5)
            assert np.allclose(ab["normal"], -ba["normal"], atol=1e-5)
    assert hits > 5


def test_bad_pair_input_raises_value_error():
    with pytest.raises(ValueError, match="radius"):
        hardbody.distance(body({"type": "sphere"}, (0, 0, 0)), body(sphere(1), (3, 0, 0)))
    with pytest.raises(ValueError, match="position"):
        hardbody.distance({"shape": sphere(1), "orientation": [1, 0, 0, 0]},
                          body(sphere(1), (3, 0, 0)))
    with pytest.raises(ValueError):
        hardbody.distance(body(sphere(1), (math.nan, 0, 0)), body(sphere(1), (3, 0, 0)))
    with pytest.raises(ValueError, match="t_max"):
        hardbody.contact_time(body(sphere(1), (0, 0, 0)), body(sphere(1), (3, 0, 0)), t_max=-1.0)
