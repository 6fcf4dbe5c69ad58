"""python/hardbody_plot.py on synthetic run directories and on tables the C++ observers wrote."""

import json
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


def write_density_profile(run, axes=("z",), species=("A", "B")):
    rows = []
    for axis in axes:
        for k in range(50):
            x = 0.2 * (k + 0.5) if axis == "r" else -5.0 + 0.2 * (k + 0.5)
            d = x if axis == "r" else 5.0 - abs(x)
            rho = [0.0 if d < 0.5 else 0.3 * (1.0 + 0.5 * math.exp(-(d - 0.5)) * math.cos(6 * d)) * (j + 1)
                   for j in range(len(species))]
            rows.append([axis, x, sum(rho), *rho])
    write_tsv(run / "density_profile.tsv", ["axis", "position", "density", *[f"density_{s}" for s in species]],
              rows, comments=["hardbody density profiles", "samples=10 species=2"])


def write_order_profile(run, axes=("z",)):
    rows = []
    for axis in axes:
        for k in range(50):
            x = -5.0 + 0.2 * (k + 0.5)
            d = 5.0 - abs(x)
            count = 0 if d < 0.5 else 100
            s2 = float("nan") if count == 0 else 0.05 + 0.5 * math.exp(-d)
            p2 = float("nan") if count == 0 else -0.4 * math.exp(-d)
            rows.append([axis, x, count, s2, p2])
    write_tsv(run / "order_profile.tsv", ["axis", "position", "count", "s2", "p2_normal"], rows,
              comments=["hardbody order profiles", "samples=10"])


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
    assert_pngs(tmp_path, ALL_PNGS + ["density_profile.png", "order_profile.png"])
    # The comment lines carry q and the D fit in key=value form.
    sys.path.insert(0, str(SCRIPT.parent))
    import hardbody_plot

    meta, cols = hardbody_plot.read_table(tmp_path / "correlations.tsv")
    assert abs(float(meta["q"]) - 2 * math.pi) < 0.1
    assert cols["time"][0] == 0.0 and cols["msd"][0] == 0.0 and cols["c2"][0] == 1.0
    assert len(cols["time"]) == 41
    # The wall profiles: axis blocks x then z (box 8, bins 0.2), positions from the box centre,
    # density = the sum of the species' densities; 300 bodies x 20 samples over 8^3.
    meta, cols = hardbody_plot.read_table(tmp_path / "density_profile.tsv", text_columns=("axis",))
    assert list(cols) == ["axis", "position", "density", "density_A", "density_B"]
    assert cols["axis"] == ["x"] * 40 + ["z"] * 40
    assert cols["position"][0] == pytest.approx(-3.9) and cols["position"][39] == pytest.approx(3.9)
    for t, a, b in zip(cols["density"], cols["density_A"], cols["density_B"]):
        assert t == pytest.approx(a + b)
    assert sum(cols["density"][:40]) / 40 == pytest.approx(300 / 512)
    assert meta["samples"] == "20" and meta["bins_z"] == "40"
    _, cols = hardbody_plot.read_table(tmp_path / "order_profile.tsv", text_columns=("axis",))
    assert list(cols) == ["axis", "position", "count", "s2", "p2_normal"]
    z = [k for k, a in enumerate(cols["axis"]) if a == "z"]
    assert cols["p2_normal"][z[0]] > cols["p2_normal"][z[20]]  # along the normal at the wall


def import_plot_module():
    sys.path.insert(0, str(SCRIPT.parent))
    import hardbody_plot

    return hardbody_plot


def write_summary(run, shape, z=None, z_error=None):
    data = {"shape": shape}
    if z is not None:
        data["Z"] = z
        data["Z_error"] = z_error
    (run / "summary.json").write_text(json.dumps(data))


def test_block_error_is_the_blocking_error_of_the_cpp_observer():
    hp = import_plot_module()
    # Fewer than 32 blocks: one level, the plain standard error of the mean.
    x = [1.0, 2.0, 4.0, 7.0]
    m = sum(x) / 4
    assert hp.block_error(x) == pytest.approx(math.sqrt(sum((v - m) ** 2 for v in x) / 12))
    assert math.isnan(hp.block_error([3.0]))  # unknown, not 0
    # 64 anti-correlated blocks: merging pairs cancels them; the largest level error is kept.
    alt = [1.0 if k % 2 else -1.0 for k in range(64)]
    assert hp.block_error(alt) == pytest.approx(math.sqrt(64 / (64 * 63)))


def test_z_plot_has_error_band_units_and_a_legend_beside_the_points(tmp_path):
    hp = import_plot_module()
    write_log(tmp_path)
    _, cols = hp.read_table(tmp_path / "log.tsv")
    err = hp.block_error(cols["Z_block"])
    plotter = hp.Plotter(tmp_path)
    fig, ax = plotter.z_figure(tmp_path / "log.tsv", {"Z": cols["Z_mean"][-1], "Z_error": err})
    # Units of the axes (README: time in sqrt(m l^2 / kT); Z is dimensionless).
    assert "sqrt(m l^2 / kT)" in ax.get_xlabel()
    assert "Z" in ax.get_ylabel() and "dimensionless" in ax.get_ylabel()
    assert "+- " in ax.get_title() and "summary.json" in ax.get_title()
    # The band: one filled polygon whose half-width at the last time is the block error.
    bands = [c for c in ax.collections if c.get_label().startswith("running mean +-")]
    assert len(bands) == 1
    verts = bands[0].get_paths()[0].vertices
    t_end = cols["time"][-1]
    ys = [y for x, y in verts if x == pytest.approx(t_end)]
    assert max(ys) - min(ys) == pytest.approx(2 * err, rel=1e-9)
    # The legend lies outside the axes: it covers no data point.
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legend_box = ax.get_legend().get_window_extent(renderer)
    axes_box = ax.get_window_extent(renderer)
    assert legend_box.x0 >= axes_box.x1
    hp.Plotter(tmp_path).plt.close(fig)


def test_z_plot_with_one_block_says_the_error_is_unknown(tmp_path):
    hp = import_plot_module()
    write_tsv(tmp_path / "log.tsv", ["time", "collisions", "Z_block", "Z_mean"], [[1.0, 10, 4.2, 4.2]])
    fig, ax = hp.Plotter(tmp_path).z_figure(tmp_path / "log.tsv", {"Z": 4.2, "Z_error": None})
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("unknown" in t for t in labels)
    assert "unknown" in ax.get_title()
    assert not [c for c in ax.collections if c.get_label().startswith("running mean +-")]


@pytest.mark.parametrize("shape", [{"type": "sphere", "radius": 0.5},
                                   [{"type": "sphere", "radius": 0.5}, {"type": "sphere", "radius": 0.7}]])
def test_sphere_runs_draw_no_c2_or_s2(tmp_path, shape):
    write_log(tmp_path)
    write_correlations(tmp_path)
    write_gr(tmp_path)
    write_nematic(tmp_path)  # an older run wrote it for spheres too
    write_summary(tmp_path, shape, 4.1, 0.01)
    (tmp_path / "c2.png").write_bytes(PNG_MAGIC)  # stale, from an earlier plot
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert_pngs(tmp_path, ["Z.png", "msd.png", "fself.png", "gr.png"])
    assert not (tmp_path / "c2.png").exists()
    assert not (tmp_path / "s2.png").exists()
    assert "sphere run" in res.stderr and "c2.png" in res.stderr


def test_mixtures_with_a_non_sphere_draw_c2_and_s2(tmp_path):
    write_log(tmp_path)
    write_correlations(tmp_path)
    write_nematic(tmp_path)
    write_summary(tmp_path, [{"type": "sphere", "radius": 0.5},
                             {"type": "ellipsoid", "semi_axes": [1.0, 0.5, 0.5]}])
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert_pngs(tmp_path, ["c2.png", "s2.png"])


def test_unreadable_summary_exits_2_naming_it(tmp_path):
    write_log(tmp_path)
    (tmp_path / "summary.json").write_text("{not json")
    res = run_plot(tmp_path)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "summary.json" in lines[0], res.stderr


def test_wall_profiles_draw_one_panel_per_axis(tmp_path):
    hp = import_plot_module()
    write_density_profile(tmp_path, axes=("x", "z"))
    write_order_profile(tmp_path, axes=("x", "z"))
    plotter = hp.Plotter(tmp_path)
    fig, axs = plotter.density_figure(tmp_path / "density_profile.tsv",
                                      {"wall_pressure": 1.234, "wall_pressure_error": 0.01})
    assert len(axs) == 2
    assert "x from the box centre" in axs[0].get_xlabel() and "z" in axs[1].get_xlabel()
    assert "1/l^3" in axs[0].get_ylabel()
    assert [l.get_label() for l in axs[0].get_lines()] == ["all species", "A", "B"]
    assert "beta P_wall = 1.234 +- 0.01" in fig._suptitle.get_text()
    # Each panel holds its own axis block (the rows below the contact distance are zeros).
    xs = axs[1].get_lines()[0].get_xdata()
    assert len(xs) == 50 and min(xs) == pytest.approx(-4.9) and max(xs) == pytest.approx(4.9)
    plotter.plt.close(fig)
    fig, axs = plotter.order_figure(tmp_path / "order_profile.tsv")
    assert len(axs) == 2
    labels = [l.get_label() for l in axs[0].get_lines() if not l.get_label().startswith("_")]
    assert labels == ["s2 (nematic)", "<P2(u.n)> (wall normal)"]
    assert len(axs[0].get_lines()[0].get_xdata()) == 46  # the empty bins (nan) are left out
    plotter.plt.close(fig)


def test_wall_profiles_are_plotted_when_present(tmp_path):
    write_log(tmp_path)
    write_density_profile(tmp_path, axes=("r",), species=("A",))
    write_order_profile(tmp_path)
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert_pngs(tmp_path, ["Z.png", "density_profile.png", "order_profile.png"])
    assert "density_profile.png" in res.stdout and "order_profile.png" in res.stdout


def test_wall_profiles_absent_give_no_note(tmp_path):
    write_log(tmp_path)
    res = run_plot(tmp_path)
    assert res.returncode == 0, res.stderr
    assert "density_profile" not in res.stderr and "order_profile" not in res.stderr
    assert not (tmp_path / "density_profile.png").exists()


def test_bad_profile_axis_exits_2_naming_the_file(tmp_path):
    write_tsv(tmp_path / "density_profile.tsv", ["axis", "position", "density"], [["w", 0.5, 1.0]])
    res = run_plot(tmp_path)
    assert res.returncode == 2
    assert "density_profile.tsv" in res.stderr and "'w'" in res.stderr


def test_profile_with_a_non_number_exits_2_naming_the_line(tmp_path):
    write_tsv(tmp_path / "order_profile.tsv", ["axis", "position", "count", "s2", "p2_normal"],
              [["z", 0.5, 3, 0.2, 0.1], ["z", 0.7, "many", 0.2, 0.1]])
    res = run_plot(tmp_path)
    assert res.returncode == 2
    assert "order_profile.tsv:3" in res.stderr
