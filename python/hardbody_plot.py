#!/usr/bin/env python3
"""Plots of a hardbody run directory: ``hardbody plot RUN_DIR``.

Reads the tables a run writes (tab-separated, ``#`` comment lines, one header row) and writes
PNG figures next to them:

    log.tsv (+ summary.json)     -> Z.png       Z per block, running mean with its block error band
    correlations.tsv             -> msd.png     MSD, log-log, with slope-1 and slope-2 guides
                                    c2.png      C2(t) (and C1(t) when present); not for spheres
                                    fself.png   F_self(q, t)
    gr.tsv (or structure.tsv)    -> gr.png      g(r)
    gr_partial.tsv (mixtures)    -> gr_partial.png  g_ab(r) of every species pair
    nematic.tsv                  -> s2.png      S2 vs time; not for spheres
    density_profile.tsv (walls)  -> density_profile.png  density of centres vs position, per
                                                        species, one panel per wall axis
    order_profile.tsv (walls)    -> order_profile.png    s2 and <P2(u.n)> vs position

Units (README): kT = 1, m = 1, lengths l as in the config, time in sqrt(m l^2 / kT). A sphere run
(summary.json: every "shape" has type "sphere") draws no c2.png or s2.png (both are 1 for
spheres) and removes stale ones. Legends sit outside the axes, beside the data.

A missing table is skipped with a note on stderr. A missing RUN_DIR, or a table (or
summary.json) that cannot be read, exits with status 2 and one message naming the directory or
the file and line. Formats: docs/observables.md.
"""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path

EXIT_BAD_INPUT = 2

# Axis labels (README "Units": kT = 1, m = 1, lengths l as in the config).
TIME_LABEL = "time t  [sqrt(m l^2 / kT)]"
LENGTH_LABEL = "r  [l]"
DENSITY_LABEL = "number density of centres  [1/l^3]"
PROFILE_AXES = {"x": "x from the box centre  [l]", "y": "y from the box centre  [l]",
                "z": "z from the box centre  [l]", "r": "distance r from the container centre  [l]"}


class TableError(Exception):
    """A table that cannot be read; the message names the file (and line)."""


def read_table(path: Path, text_columns: tuple[str, ...] = ()) -> tuple[dict[str, str], dict[str, list]]:
    """Read a hardbody TSV table.

    Returns (meta, columns): ``meta`` holds the ``key=value`` pairs of the ``#`` comment lines,
    ``columns`` maps each header name to its values (``nan``/``inf`` allowed). The columns named
    in ``text_columns`` (e.g. ``axis`` of density_profile.tsv) are kept as strings; all others must be
    numbers.
    """
    meta: dict[str, str] = {}
    header: list[str] | None = None
    rows: list[list[float]] = []
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as e:
        raise TableError(f"{path}: cannot read ({e})") from e
    for lineno, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        if line.startswith("#"):
            for word in line[1:].split():
                key, sep, value = word.partition("=")
                if sep:
                    meta[key] = value
            continue
        fields = line.split("\t")
        if header is None:
            header = [f.strip() for f in fields]
            continue
        if len(fields) != len(header):
            raise TableError(
                f"{path}:{lineno}: {len(fields)} fields, header has {len(header)}")
        try:
            rows.append([f.strip() if name in text_columns else float(f) for name, f in zip(header, fields)])
        except ValueError as e:
            raise TableError(f"{path}:{lineno}: not a number ({e})") from e
    if header is None:
        raise TableError(f"{path}: no header row")
    columns = {name: [row[k] for row in rows] for k, name in enumerate(header)}
    return meta, columns


def require(columns: dict[str, list[float]], path: Path, *names: str) -> None:
    missing = [n for n in names if n not in columns]
    if missing:
        raise TableError(f"{path}: missing column(s) {', '.join(missing)}")


def finite_pairs(xs, ys, positive=False):
    """(x, y) pairs where both are finite (and > 0 when ``positive``, for log axes)."""
    out_x, out_y = [], []
    for x, y in zip(xs, ys):
        if math.isfinite(x) and math.isfinite(y) and (not positive or (x > 0 and y > 0)):
            out_x.append(x)
            out_y.append(y)
    return out_x, out_y


def note(msg: str) -> None:
    print(f"hardbody plot: {msg}", file=sys.stderr)


def block_error(values: list[float], min_blocks: int = 16) -> float:
    """Standard error of the mean of equal-duration block means: the Flyvbjerg-Petersen blocking
    of src/observers/block_average.hpp (largest error over the pairwise-merged levels while at
    least ``min_blocks`` remain). NaN with fewer than two blocks (unknown, never a false 0)."""
    x = [v for v in values if math.isfinite(v)]
    if len(x) < 2:
        return math.nan
    best = 0.0
    while True:
        n = len(x)
        m = sum(x) / n
        se = math.sqrt(sum((v - m) ** 2 for v in x) / (n * (n - 1)))
        best = max(best, se)
        if n // 2 < min_blocks:
            return best
        x = [0.5 * (x[2 * k] + x[2 * k + 1]) for k in range(n // 2)]


def read_summary(run_dir: Path) -> dict:
    """summary.json of the run, or {} when there is none (an unfinished run)."""
    path = run_dir / "summary.json"
    if not path.is_file():
        return {}
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise TableError(f"{path}: cannot read ({e})") from e
    if not isinstance(data, dict):
        raise TableError(f"{path}: not a JSON object")
    return data


def is_sphere_run(summary: dict) -> bool:
    """Every species a sphere (summary.json "shape": one object, or a list for mixtures)."""
    shape = summary.get("shape")
    shapes = shape if isinstance(shape, list) else [shape]
    return bool(shapes) and all(isinstance(s, dict) and s.get("type") == "sphere" for s in shapes)


class Plotter:
    def __init__(self, run_dir: Path):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        self.plt = plt
        self.run_dir = run_dir
        self.written: list[Path] = []

    def save(self, fig, name: str) -> None:
        """Write RUN_DIR/name atomically (temporary name, then rename)."""
        final = self.run_dir / name
        tmp = self.run_dir / f".{name}.tmp"
        fig.tight_layout()
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
        self.plt.close(fig)
        os.replace(tmp, final)
        self.written.append(final)

    def figure(self, xlabel: str, ylabel: str, title: str | None = None):
        fig, ax = self.plt.subplots(figsize=(7.2, 4.2))
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if title:
            ax.set_title(title, fontsize=10)
        ax.grid(True, alpha=0.3)
        return fig, ax

    @staticmethod
    def legend(ax) -> None:
        """Legend outside the axes, to the right, so that it never covers data."""
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=9)

    def z_figure(self, path: Path, summary: dict | None = None):
        """Z per block (dots), the running mean (line) with a +-1 block-error band (the error of
        the mean of the blocks so far, as summary.json computes it at the end), and the final
        Z +- Z_error of summary.json in the title when present."""
        _, c = read_table(path)
        require(c, path, "time", "Z_block", "Z_mean")
        summary = summary or {}
        title = "compressibility factor"
        z, z_err = summary.get("Z"), summary.get("Z_error")
        if isinstance(z, (int, float)):
            err = f"{z_err:.2g}" if isinstance(z_err, (int, float)) else "unknown (< 2 blocks)"
            title += f"   Z = {z:.6g} +- {err} (summary.json)"
        fig, ax = self.figure(TIME_LABEL, "Z = beta P / rho  [dimensionless]", title)
        x, y = finite_pairs(c["time"], c["Z_block"])
        ax.plot(x, y, ".", ms=3, alpha=0.6, label="Z per block")
        tm, zm = finite_pairs(c["time"], c["Z_mean"])
        ax.plot(tm, zm, "-", lw=1.5, label="running mean")
        # Band: the block error of the first k blocks, at up to 200 k (the last one exact).
        blocks = c["Z_block"]
        n = len(blocks)
        ks = sorted({max(2, round(n * j / 200)) for j in range(1, 201)} | {n}) if n >= 2 else []
        bt, lo, hi = [], [], []
        for k in ks:
            e = block_error(blocks[:k])
            t, m = c["time"][k - 1], c["Z_mean"][k - 1]
            if math.isfinite(e) and math.isfinite(t) and math.isfinite(m):
                bt.append(t)
                lo.append(m - e)
                hi.append(m + e)
        if bt:
            ax.fill_between(bt, lo, hi, color="C1", alpha=0.3, lw=0, label="running mean +- block error")
        else:
            ax.plot([], [], " ", label="block error unknown (< 2 blocks)")
        self.legend(ax)
        return fig, ax

    def log(self, path: Path, summary: dict | None = None) -> None:
        fig, _ = self.z_figure(path, summary)
        self.save(fig, "Z.png")

    def correlations(self, path: Path, spheres: bool = False) -> None:
        meta, c = read_table(path)
        require(c, path, "time", "msd", "c2", "fself")
        t = c["time"]

        title = "mean-squared displacement"
        if "D" in meta and meta["D"].lower() != "nan":
            title += f"   D = {float(meta['D']):.4g} (fit t in [{float(meta.get('fit_t_from', 'nan')):.3g}, " \
                     f"{float(meta.get('fit_t_to', 'nan')):.3g}])"
        fig, ax = self.figure(TIME_LABEL, "MSD  [l^2]", title)
        x, y = finite_pairs(t, c["msd"], positive=True)
        if x:
            ax.loglog(x, y, "o-", ms=3, label="MSD")
            # Guides: slope 2 (ballistic) through the first point, slope 1 (diffusive) through
            # the last one.
            ax.loglog(x, [y[0] * (xi / x[0]) ** 2 for xi in x], "--", lw=1, color="gray",
                      label="slope 2")
            ax.loglog(x, [y[-1] * (xi / x[-1]) for xi in x], ":", lw=1.2, color="black",
                      label="slope 1")
            self.legend(ax)
        self.save(fig, "msd.png")

        if not spheres:  # C2 = C1 = 1 for spheres: nothing to see
            fig, ax = self.figure(TIME_LABEL, "orientational correlation", "C2(t) = <P2(u(0).u(t))>")
            x, y = finite_pairs(t, c["c2"])
            ax.plot(x, y, "-", label="C2")
            if "c1" in c:
                x, y = finite_pairs(t, c["c1"])
                ax.plot(x, y, "--", label="C1")
            ax.axhline(0.0, color="gray", lw=0.8)
            self.legend(ax)
            self.save(fig, "c2.png")

        q = meta.get("q")
        fig, ax = self.figure(TIME_LABEL, "F_self(q, t)",
                              f"self intermediate scattering function, q = {float(q):.4g} / l"
                              if q and q.lower() != "nan" else "self intermediate scattering function")
        x, y = finite_pairs(t, c["fself"])
        ax.plot(x, y, "-")
        ax.axhline(0.0, color="gray", lw=0.8)
        self.save(fig, "fself.png")

    def simple(self, path: Path, x: str, y: str, name: str, title: str,
               hline: float | None = None, xlabel: str | None = None, ylabel: str | None = None) -> None:
        """One column against another, e.g. g(r) or S2(t)."""
        _, c = read_table(path)
        require(c, path, x, y)
        fig, ax = self.figure(xlabel or x, ylabel or y, title)
        xs, ys = finite_pairs(c[x], c[y])
        ax.plot(xs, ys, "-")
        if hline is not None:
            ax.axhline(hline, color="gray", lw=0.8)
        self.save(fig, name)

    def gr(self, path: Path) -> None:
        self.simple(path, "r", "g", "gr.png", "radial distribution function g(r)", hline=1.0,
                    xlabel=LENGTH_LABEL, ylabel="g(r)")

    def gr_partial(self, path: Path) -> None:
        _, c = read_table(path)
        require(c, path, "r")
        pairs = [k for k in c if k.startswith("g_")]
        if not pairs:
            raise TableError(f"{path}: no g_<a>_<b> column")
        fig, ax = self.figure(LENGTH_LABEL, "g_ab(r)", "partial radial distribution functions")
        for k in pairs:
            xs, ys = finite_pairs(c["r"], c[k])
            ax.plot(xs, ys, "-", label=k[2:].replace("_", "-", 1))
        ax.axhline(1.0, color="gray", lw=0.8)
        self.legend(ax)
        self.save(fig, "gr_partial.png")

    @staticmethod
    def profile_blocks(path: Path, columns: dict[str, list]) -> list[tuple[str, list[int]]]:
        """The axis blocks of a profile table: [(axis, row indices)] in table order."""
        blocks: list[tuple[str, list[int]]] = []
        for i, a in enumerate(columns["axis"]):
            if a not in PROFILE_AXES:
                raise TableError(f"{path}: axis '{a}' is not one of x, y, z, r")
            if not blocks or blocks[-1][0] != a:
                blocks.append((a, []))
            blocks[-1][1].append(i)
        if not blocks:
            raise TableError(f"{path}: no rows")
        return blocks

    def panels(self, n: int, ylabel: str, title: str):
        fig, axs = self.plt.subplots(1, n, figsize=(5.2 * n + 1.6, 4.2), squeeze=False)
        axs = list(axs[0])
        for ax in axs:
            ax.grid(True, alpha=0.3)
        axs[0].set_ylabel(ylabel)
        fig.suptitle(title, fontsize=10)
        return fig, axs

    def density_figure(self, path: Path, summary: dict | None = None):
        """density_profile.tsv: one panel per wall axis (x, y, z: position from the box centre; r:
        radius), the density of all centres and, for mixtures, of each species; the wall pressure
        of summary.json in the title when present."""
        _, c = read_table(path, text_columns=("axis",))
        require(c, path, "axis", "position", "density")
        species = [k for k in c if k.startswith("density_")]
        blocks = self.profile_blocks(path, c)
        title = "density profiles at the walls"
        p, p_err = (summary or {}).get("wall_pressure"), (summary or {}).get("wall_pressure_error")
        if isinstance(p, (int, float)):
            err = f"{p_err:.2g}" if isinstance(p_err, (int, float)) else "unknown (< 2 blocks)"
            title += f"   beta P_wall = {p:.6g} +- {err} (summary.json)"
        fig, axs = self.panels(len(blocks), DENSITY_LABEL, title)
        for ax, (axis, rows) in zip(axs, blocks):
            x = [c["position"][i] for i in rows]
            ax.set_xlabel(PROFILE_AXES[axis])
            xs, ys = finite_pairs(x, [c["density"][i] for i in rows])
            ax.plot(xs, ys, "-", lw=1.4, color="black", label="all species")
            if len(species) > 1:
                for k in species:
                    xs, ys = finite_pairs(x, [c[k][i] for i in rows])
                    ax.plot(xs, ys, "-", lw=1.0, label=k[len("density_"):])
        self.legend(axs[-1])
        return fig, axs

    def density_profile(self, path: Path, summary: dict | None = None) -> None:
        fig, _ = self.density_figure(path, summary)
        self.save(fig, "density_profile.png")

    def order_figure(self, path: Path):
        """order_profile.tsv: per wall axis, s2 (nematic order of the long axes in each bin) and
        p2_normal = <P2(u.n)> (1: along the wall normal, -1/2: in the wall's plane)."""
        _, c = read_table(path, text_columns=("axis",))
        require(c, path, "axis", "position", "count", "s2", "p2_normal")
        blocks = self.profile_blocks(path, c)
        fig, axs = self.panels(len(blocks), "order parameter", "orientational order profiles (bodies that are not spheres)")
        for ax, (axis, rows) in zip(axs, blocks):
            x = [c["position"][i] for i in rows]
            ax.set_xlabel(PROFILE_AXES[axis])
            for key, label in (("s2", "s2 (nematic)"), ("p2_normal", "<P2(u.n)> (wall normal)")):
                xs, ys = finite_pairs(x, [c[key][i] for i in rows])
                ax.plot(xs, ys, ".-", ms=2, lw=1.0, label=label)
            for y in (0.0, -0.5, 1.0):
                ax.axhline(y, color="gray", lw=0.6, ls=":" if y else "-")
        self.legend(axs[-1])
        return fig, axs

    def order_profile(self, path: Path) -> None:
        fig, _ = self.order_figure(path)
        self.save(fig, "order_profile.png")

    def nematic(self, path: Path) -> None:
        self.simple(path, "time", "S2", "s2.png", "nematic order parameter", xlabel=TIME_LABEL,
                    ylabel="S2")


def main(argv: list[str]) -> int:
    if len(argv) != 1 or argv[0] in ("-h", "--help"):
        print("usage: hardbody plot RUN_DIR", file=sys.stderr)
        return EXIT_BAD_INPUT
    run_dir = Path(argv[0])
    if not run_dir.is_dir():
        note(f"run directory '{run_dir}' does not exist or is not a directory")
        return EXIT_BAD_INPUT

    plotter = Plotter(run_dir)
    try:
        summary = read_summary(run_dir)
    except TableError as e:
        note(str(e))
        return EXIT_BAD_INPUT
    spheres = is_sphere_run(summary)
    gr_file = next((run_dir / n for n in ("gr.tsv", "structure.tsv") if (run_dir / n).is_file()), None)
    jobs = [
        (run_dir / "log.tsv", lambda p: plotter.log(p, summary), "Z.png"),
        (run_dir / "correlations.tsv", lambda p: plotter.correlations(p, spheres),
         "msd.png, fself.png" if spheres else "msd.png, c2.png, fself.png"),
        (gr_file or run_dir / "gr.tsv", plotter.gr, "gr.png"),
    ]
    if spheres:
        # C2, C1 and S2 are identically 1 for spheres: no c2.png or s2.png (stale ones go).
        stale = [name for name in ("c2.png", "s2.png") if (run_dir / name).is_file()]
        for name in stale:
            (run_dir / name).unlink()
        note("sphere run: no c2.png or s2.png (orientational order is 1 for spheres)"
             + (f"; removed stale {', '.join(stale)}" if stale else ""))
    else:
        jobs.append((run_dir / "nematic.tsv", plotter.nematic, "s2.png"))
    if (run_dir / "gr_partial.tsv").is_file():  # mixtures only: no note when absent
        jobs.append((run_dir / "gr_partial.tsv", plotter.gr_partial, "gr_partial.png"))
    if (run_dir / "density_profile.tsv").is_file():  # runs with walls only: no note when absent
        jobs.append((run_dir / "density_profile.tsv", lambda p: plotter.density_profile(p, summary),
                     "density_profile.png"))
    if (run_dir / "order_profile.tsv").is_file():
        jobs.append((run_dir / "order_profile.tsv", plotter.order_profile, "order_profile.png"))
    try:
        for path, plot, outputs in jobs:
            if not path.is_file():
                what = "gr.tsv or structure.tsv" if path == (gr_file or run_dir / "gr.tsv") else path.name
                note(f"no {what} in {run_dir}: skipping {outputs}")
                continue
            plot(path)
    except TableError as e:
        note(str(e))
        return EXIT_BAD_INPUT
    for p in plotter.written:
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
