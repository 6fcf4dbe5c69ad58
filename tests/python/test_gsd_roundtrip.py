"""hardbody's GSD writer, read back by the reference gsd package (python3-gsd 2.7).

The C++ helper named by $HB_GSD_SAMPLE_WRITER writes trajectory.gsd, checkpoint.gsd and
expected.json (every value the files must yield, including the hoomd schema's rule that a chunk
missing from a frame is taken from frame 0 or the default). Every field is compared exactly.
"""
import json
import os
import subprocess

import numpy
import pytest

# Debian's python3-gsd; a missing package is a failure, not a skip.
import gsd.fl as gsd_fl
import gsd.hoomd as gsd_hoomd
import gsd.pygsd as gsd_pygsd


@pytest.fixture(scope="module")
def writer():
    path = os.environ.get("HB_GSD_SAMPLE_WRITER")
    if not path:
        pytest.fail("HB_GSD_SAMPLE_WRITER is not set (run through ctest)")
    return path


@pytest.fixture(scope="module")
def sample(writer, tmp_path_factory):
    out = tmp_path_factory.mktemp("gsd")
    subprocess.run([writer, str(out)], check=True)
    with open(out / "expected.json") as f:
        expected = json.load(f)
    return out, expected


def exact(actual, expected, dtype):
    actual = numpy.asarray(actual)
    assert actual.dtype == numpy.dtype(dtype)
    want = numpy.asarray(expected, dtype=numpy.float64)
    assert actual.size == want.size
    numpy.testing.assert_array_equal(actual.astype(numpy.float64).reshape(want.shape), want)


def check_snapshot(snap, want):
    p = snap.particles
    assert snap.configuration.step == want["step"]
    assert snap.configuration.dimensions == want["dimensions"]
    exact(snap.configuration.box, want["box"], numpy.float32)
    assert p.N == want["N"]
    N = want["N"]
    exact(p.position, numpy.reshape(want["position"], (N, 3)), numpy.float32)
    exact(p.orientation, numpy.reshape(want["orientation"], (N, 4)), numpy.float32)
    exact(p.velocity, numpy.reshape(want["velocity"], (N, 3)), numpy.float32)
    exact(p.angmom, numpy.reshape(want["angmom"], (N, 4)), numpy.float32)
    exact(p.image, numpy.reshape(want["image"], (N, 3)), numpy.int32)
    exact(p.typeid, want["typeid"], numpy.uint32)
    assert list(p.types) == want["types"]
    assert list(p.type_shapes) == [json.loads(s) for s in want["type_shapes"]]
    assert set(snap.log) == set(want["log"])
    for key, log in want["log"].items():
        value = numpy.asarray(snap.log[key])
        assert value.dtype == numpy.float64
        want_values = numpy.asarray(log["values"], dtype=numpy.float64).reshape(log["shape"])
        # bit-exact doubles (the sign of zero included)
        numpy.testing.assert_array_equal(value.reshape(log["shape"]).view(numpy.uint64),
                                         want_values.view(numpy.uint64))


def test_file_layer_header(sample):
    out, expected = sample
    for name, frames in (("trajectory.gsd", len(expected["trajectory"])), ("checkpoint.gsd", 1)):
        with gsd_fl.open(name=str(out / name), mode="rb") as f:
            assert f.application == "hardbody"
            assert f.schema == "hoomd"
            assert tuple(f.schema_version) == (1, 4)
            assert tuple(f.gsd_version) == (2, 0)
            assert f.nframes == frames


def test_trajectory_via_gsd_hoomd(sample):
    out, expected = sample
    with gsd_hoomd.open(name=str(out / "trajectory.gsd"), mode="rb") as traj:
        assert len(traj) == len(expected["trajectory"])
        for snap, want in zip(traj, expected["trajectory"]):
            check_snapshot(snap, want)


def test_checkpoint_via_gsd_hoomd(sample):
    out, expected = sample
    with gsd_hoomd.open(name=str(out / "checkpoint.gsd"), mode="rb") as traj:
        assert len(traj) == 1
        check_snapshot(traj[0], expected["checkpoint"])
    assert not (out / "checkpoint.gsd.tmp").exists()


def test_raw_chunks(sample):
    """Chunk types and shapes as the schema prescribes, read with the C file layer."""
    out, expected = sample
    want = expected["trajectory"][0]
    N = want["N"]
    with gsd_fl.open(name=str(out / "trajectory.gsd"), mode="rb") as f:
        shapes = {
            "configuration/step": (numpy.uint64, (1,)),
            "configuration/box": (numpy.float32, (6,)),
            "particles/N": (numpy.uint32, (1,)),
            "particles/typeid": (numpy.uint32, (N,)),
            "particles/position": (numpy.float32, (N, 3)),
            "particles/orientation": (numpy.float32, (N, 4)),
            "particles/velocity": (numpy.float32, (N, 3)),
            "particles/angmom": (numpy.float32, (N, 4)),
            "particles/image": (numpy.int32, (N, 3)),
            "log/particles/hardbody/position_double": (numpy.float64, (N, 3)),
            "log/hardbody/time": (numpy.float64, (1,)),
        }
        for name, (dtype, shape) in shapes.items():
            data = f.read_chunk(frame=0, name=name)
            assert data.dtype == numpy.dtype(dtype), name
            assert data.shape == shape, name
        types = f.read_chunk(frame=0, name="particles/types")
        assert types.dtype == numpy.int8
        width = max(len(t) for t in want["types"]) + 1
        assert types.shape == (len(want["types"]), width)
        shapes_raw = f.read_chunk(frame=0, name="particles/type_shapes")
        assert shapes_raw.dtype == numpy.int8
        assert shapes_raw.shape[0] == len(want["type_shapes"])
        # frame 1 repeats frame 0's attributes: they are left out, as the schema allows
        for name in ("particles/types", "particles/type_shapes", "particles/typeid",
                     "particles/velocity"):
            assert not f.chunk_exists(frame=1, name=name), name
        # every log chunk is in every frame (and in frame 0, as the schema requires)
        for i in range(f.nframes):
            for key in want["log"]:
                assert f.chunk_exists(frame=i, name="log/" + key)


def test_pure_python_reader_agrees(sample):
    """gsd.pygsd (an independent pure-Python reader) sees the same chunks."""
    out, expected = sample
    with open(out / "trajectory.gsd", "rb") as fo, \
            gsd_fl.open(name=str(out / "trajectory.gsd"), mode="rb") as f:
        p = gsd_pygsd.GSDFile(fo)
        assert p.nframes == f.nframes
        for i in range(f.nframes):
            for name in f.find_matching_chunk_names(""):
                assert p.chunk_exists(frame=i, name=name) == f.chunk_exists(frame=i, name=name)
                if f.chunk_exists(frame=i, name=name):
                    numpy.testing.assert_array_equal(p.read_chunk(frame=i, name=name),
                                                     f.read_chunk(frame=i, name=name))


def test_grown_index_and_namelist(sample):
    """A file whose index and namelist were moved to larger blocks reads back in full."""
    out, expected = sample
    big = expected["big"]
    with gsd_fl.open(name=str(out / "big.gsd"), mode="rb") as f:
        assert f.nframes == big["frames"]
        names = f.find_matching_chunk_names("")
        assert len(names) == big["names"] + 1
        for i in range(big["frames"]):
            numpy.testing.assert_array_equal(f.read_chunk(frame=i, name="value"), [[i, 7]])
            name = big["prefix"] + str(i % big["names"])
            numpy.testing.assert_array_equal(f.read_chunk(frame=i, name=name), [-i])
            assert not f.chunk_exists(frame=i, name=big["prefix"] + str((i + 1) % big["names"]))


def test_hardbody_reads_reference_files(writer, tmp_path):
    """hardbody's reader on a file from gsd.hoomd: same values as gsd.hoomd reads back."""
    path = tmp_path / "reference.gsd"
    rng = numpy.random.default_rng(5)
    with gsd_hoomd.open(name=str(path), mode="wb") as traj:
        for i, N in enumerate([4, 4, 2, 2]):
            snap = gsd_hoomd.Snapshot()
            snap.configuration.step = 10 * i
            snap.configuration.box = [3, 4, 5, 0, 0.5, 0]
            snap.particles.N = N
            snap.particles.types = ["A", "a_longer_name"]
            snap.particles.type_shapes = [{"type": "Sphere", "diameter": 1.5},
                                          {"type": "Ellipsoid", "a": 1.0, "b": 2.0, "c": 0.25}]
            snap.particles.typeid = numpy.arange(N, dtype=numpy.uint32) % 2
            snap.particles.position = rng.random((N, 3), dtype=numpy.float32)
            if i != 1:  # frame 1 falls back to frame 0's orientation
                q = rng.random((N, 4))
                snap.particles.orientation = (q / numpy.linalg.norm(q, axis=1)[:, None]).astype(
                    numpy.float32)
            snap.particles.velocity = rng.random((N, 3), dtype=numpy.float32)
            snap.log["hardbody/time"] = numpy.array([0.1 * i + 1e-12])
            snap.log["particles/hardbody/x"] = rng.random((N, 3))
            traj.append(snap)
    result = subprocess.run([writer, "--dump", str(path)], check=True, capture_output=True,
                            text=True)
    frames = json.loads(result.stdout)
    with gsd_hoomd.open(name=str(path), mode="rb") as traj:
        assert len(frames) == len(traj)
        for snap, got in zip(traj, frames):
            check_snapshot(snap, got)


def test_corrupt_file_is_reported(writer, sample, tmp_path):
    """A truncated file: hardbody's reader names the file and the problem."""
    out, _ = sample
    data = (out / "trajectory.gsd").read_bytes()
    path = tmp_path / "truncated.gsd"
    path.write_bytes(data[:-7])
    result = subprocess.run([writer, "--dump", str(path)], capture_output=True, text=True)
    assert result.returncode == 1
    assert str(path) in result.stderr
    assert "out of bounds" in result.stderr
