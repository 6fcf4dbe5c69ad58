"""python/hardbody_plot.py on synthetic run directories and on tables the C++ observers wrote."""

import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(os.environ.get(
    "HB_PLOT_SCRIPT", Path(__file__).resolve().parents[2] / "python" / "hardbody_plot.py"))
WRITER = os.environ.get("HB_OBSERVER_TABLE_WRITER")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
ALL_PNGS = ["Z.png", "msd.png", "c2.png", "fself.png", "gr.png", "s2.png"]


def run_plot(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)],
                          capture_output=True, text=True, timeout=120)


def write_tsv(path, header, rows, comments=()):
    lines = [f"# {c}" for c in comments] + ["\t".join(header)]
    lines += ["\t".join(f"{x:.10g}" if isinstance(x, float) else str(x) for x in row)
              for row in rows]
    path.write_text("\n".join(lines) + "\n")


def write_log(run):
    rows = []
    mean = 0.0
    for k in range(1, 41):
        z = 4.0 + 0.3 * math.sin(k)
        mean += (z - mean) / k
        rows.append([float(k), 1000 * k, z, mean, 1.0, 1e-12 * k, 12.5])
    write_tsv(run / "log.tsv", ["time", "collisions", "Z_block", "Z_mean", "temperature",
                                "energy_drift", "collision_rate"], rows)


def write_correlations(run):
    rows = []
    for k in range(0, 51):
        t = 0.1 * k
        msd = 3.0 * t * t if t < 1 else 3.0 + 6.0 * 0.5 * (t - 1.0)
        a2 = float("nan") if k == 0 else 0.1
        rows.append([t, msd, 51 - k, math.exp(-t), math.exp(-2 * t), math.exp(-0.5 * t), a2])
    write_tsv(run / "correlations.tsv", ["time", "msd", "msd_samples", "c2", "fself", "c1", "alpha2"],
              rows, comments=["hardbody time correlations",
                              "interval=0.1 origin_every=10 max_lag_samples=50 samples=500",
                              "q=6.283185307 q_target=6.283185307 q_vectors=15",
                              "D=0.5 D_error=0.01 intercept=-1 fit_t_from=2.5 fit_t_to=5 fit_points=26"])


def write_gr(run, name="gr.tsv"):
    rows = []
    for k in range(100):
        r = 0.05 * (k + 0.5)
        g = 0.0 if r < 1 else 1.0 + math.exp(-(r - 1)) * math.cos(6 * (r - 1))
        rows.append([r, g, 0.1 * k, 10 * k])
    write_tsv(run / name, ["r", "g", "n_r", "pairs"], rows,
              comments=["hardbody radial distribution function", "samples=10 N=500 r_max=5 bins=100"])


def write_nematic(run):
    rows = [[float(k), 0.02 + 0.001 * k, 0.0, 0.0, 1.0] for k in range(20)]
    write_tsv(run / "nematic.tsv", ["time", "S2", "director_x", "director_y", "director_z"], rows,
              comments=["hardbody nematic order", "S2_mean=0.03 S2_error=0.001 samples=20"])


def assert_pngs(run, names):
    for name in names:
        p = run / name
        assert p.is_file(), f"{name} not written"
        data = p.read_bytes()
        assert data.startswith(PNG_MAGIC), f"{name} is not a PNG"
        assert len(data) > 2000, f"{name} is suspiciously small ({len(data)} bytes)"
    leftovers = [p.name for p in run.iterdir() if p.name.endswith(".tmp")]
    assert not leftovers, f"temporary files left: {leftovers}"


def test_full_run_dir_writes_every_png(tmp_path):
    write_log(tmp_path)
    write_correlations(tmp_path)
    write_gr(tmp_path)
    write_nematic(tmp_path)
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert_pngs(tmp_path, ALL_PNGS)
    assert res.stderr == ""


def test_missing_tables_are_skipped_with_a_note(tmp_path):
    write_log(tmp_path)
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert_pngs(tmp_path, ["Z.png"])
    for name in ["msd.png", "c2.png", "fself.png", "gr.png", "s2.png"]:
        assert not (tmp_path / name).exists()
    assert "correlations.tsv" in res.stderr and "skipping" in res.stderr
    assert "structure.tsv" in res.stderr


def test_structure_tsv_is_read_as_gr(tmp_path):
    write_gr(tmp_path, "structure.tsv")
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert_pngs(tmp_path, ["gr.png"])
    assert "log.tsv" in res.stderr  # noted as missing


def test_missing_run_dir_exits_2_with_one_message(tmp_path):
    missing = tmp_path / "no-such-run"
    res = run_plot(missing)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and str(missing) in lines[0], res.stderr
    assert res.stdout == ""


def test_malformed_table_exits_2_naming_file_and_line(tmp_path):
    write_log(tmp_path)
    with open(tmp_path / "log.tsv", "a") as f:
        f.write("41\t1\tnot-a-number\t4\t1\t0\t12\n")
    res = run_plot(tmp_path)
    assert res.returncode == 2
    assert "log.tsv:42" in res.stderr, res.stderr


def test_missing_column_exits_2(tmp_path):
    write_tsv(tmp_path / "log.tsv", ["time", "collisions"], [[1.0, 3]])
    res = run_plot(tmp_path)
    assert res.returncode == 2
    assert "Z_block" in res.stderr


@pytest.mark.skipif(not WRITER, reason="HB_OBSERVER_TABLE_WRITER not set (run through ctest)")
def test_tables_written_by_the_observers(tmp_path):
    subprocess.run([WRITER, str(tmp_path)], check=True, timeout=120)
    write_log(tmp_path)
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert_pngs(tmp_path, ALL_PNGS)
    # The comment lines carry q and the D fit in key=value form.
    sys.path.insert(0, str(SCRIPT.parent))
    import hardbody_plot

    meta, cols = hardbody_plot.read_table(tmp_path / "correlations.tsv")
    assert abs(float(meta["q"]) - 2 * math.pi) < 0.1
    assert cols["time"][0] == 0.0 and cols["msd"][0] == 0.0 and cols["c2"][0] == 1.0
    assert len(cols["time"]) == 41
