#!/usr/bin/env python3
"""Plots of a hardbody run directory: ``hardbody plot RUN_DIR``.

Reads the tables a run writes (tab-separated, ``#`` comment lines, one header row) and writes
PNG figures next to them:

    log.tsv                      -> Z.png       Z per block and running mean vs time
    correlations.tsv             -> msd.png     MSD, log-log, with slope-1 and slope-2 guides
                                    c2.png      C2(t) (and C1(t) when present)
                                    fself.png   F_self(q, t)
    gr.tsv (or structure.tsv)    -> gr.png      g(r)
    gr_partial.tsv (mixtures)    -> gr_partial.png  g_ab(r) of every species pair
    nematic.tsv                  -> s2.png      S2 vs time

A missing table is skipped with a note on stderr. A missing RUN_DIR, or a table that cannot be
read, exits with status 2 and one message naming the directory or the file and line.
Formats: docs/observables.md.
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

EXIT_BAD_INPUT = 2


class TableError(Exception):
    """A table that cannot be read; the message names the file (and line)."""


def read_table(path: Path) -> tuple[dict[str, str], dict[str, list[float]]]:
    """Read a hardbody TSV table.

    Returns (meta, columns): ``meta`` holds the ``key=value`` pairs of the ``#`` comment lines,
    ``columns`` maps each header name to its values (``nan``/``inf`` allowed).
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
            rows.append([float(f) for f in fields])
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
        fig.savefig(tmp, format="png", dpi=110)
        self.plt.close(fig)
        os.replace(tmp, final)
        self.written.append(final)

    def figure(self, xlabel: str, ylabel: str, title: str | None = None):
        fig, ax = self.plt.subplots(figsize=(6.0, 4.2))
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if title:
            ax.set_title(title, fontsize=10)
        ax.grid(True, alpha=0.3)
        return fig, ax

    def log(self, path: Path) -> None:
        _, c = read_table(path)
        require(c, path, "time", "Z_block", "Z_mean")
        fig, ax = self.figure("time", "Z = beta P / rho", "compressibility factor")
        x, y = finite_pairs(c["time"], c["Z_block"])
        ax.plot(x, y, ".", ms=3, alpha=0.6, label="Z per block")
        x, y = finite_pairs(c["time"], c["Z_mean"])
        ax.plot(x, y, "-", lw=1.5, label="running mean")
        ax.legend()
        self.save(fig, "Z.png")

    def correlations(self, path: Path) -> None:
        meta, c = read_table(path)
        require(c, path, "time", "msd", "c2", "fself")
        t = c["time"]

        title = "mean-squared displacement"
        if "D" in meta and meta["D"].lower() != "nan":
            title += f"   D = {float(meta['D']):.4g} (fit t in [{float(meta.get('fit_t_from', 'nan')):.3g}, " \
                     f"{float(meta.get('fit_t_to', 'nan')):.3g}])"
        fig, ax = self.figure("time", "MSD", title)
        x, y = finite_pairs(t, c["msd"], positive=True)
        if x:
            ax.loglog(x, y, "o-", ms=3, label="MSD")
            # Guides: slope 2 (ballistic) through the first point, slope 1 (diffusive) through
            # the last one.
            ax.loglog(x, [y[0] * (xi / x[0]) ** 2 for xi in x], "--", lw=1, color="gray",
                      label="slope 2")
            ax.loglog(x, [y[-1] * (xi / x[-1]) for xi in x], ":", lw=1.2, color="black",
                      label="slope 1")
            ax.legend()
        self.save(fig, "msd.png")

        fig, ax = self.figure("time", "orientational correlation", "C2(t) = <P2(u(0).u(t))>")
        x, y = finite_pairs(t, c["c2"])
        ax.plot(x, y, "-", label="C2")
        if "c1" in c:
            x, y = finite_pairs(t, c["c1"])
            ax.plot(x, y, "--", label="C1")
        ax.axhline(0.0, color="gray", lw=0.8)
        ax.legend()
        self.save(fig, "c2.png")

        q = meta.get("q")
        fig, ax = self.figure("time", "F_self(q, t)",
                              f"self intermediate scattering function, q = {float(q):.4g}"
                              if q and q.lower() != "nan" else "self intermediate scattering function")
        x, y = finite_pairs(t, c["fself"])
        ax.plot(x, y, "-")
        ax.axhline(0.0, color="gray", lw=0.8)
        self.save(fig, "fself.png")

    def simple(self, path: Path, x: str, y: str, name: str, title: str,
               hline: float | None = None) -> None:
        """One column against another, e.g. g(r) or S2(t)."""
        _, c = read_table(path)
        require(c, path, x, y)
        fig, ax = self.figure(x, y, title)
        xs, ys = finite_pairs(c[x], c[y])
        ax.plot(xs, ys, "-")
        if hline is not None:
            ax.axhline(hline, color="gray", lw=0.8)
        self.save(fig, name)

    def gr(self, path: Path) -> None:
        self.simple(path, "r", "g", "gr.png", "radial distribution function g(r)", hline=1.0)

    def gr_partial(self, path: Path) -> None:
        _, c = read_table(path)
        require(c, path, "r")
        pairs = [k for k in c if k.startswith("g_")]
        if not pairs:
            raise TableError(f"{path}: no g_<a>_<b> column")
        fig, ax = self.figure("r", "g_ab(r)", "partial radial distribution functions")
        for k in pairs:
            xs, ys = finite_pairs(c["r"], c[k])
            ax.plot(xs, ys, "-", label=k[2:].replace("_", "-", 1))
        ax.axhline(1.0, color="gray", lw=0.8)
        ax.legend()
        self.save(fig, "gr_partial.png")

    def nematic(self, path: Path) -> None:
        self.simple(path, "time", "S2", "s2.png", "nematic order parameter")


def main(argv: list[str]) -> int:
    if len(argv) != 1 or argv[0] in ("-h", "--help"):
        print("usage: hardbody plot RUN_DIR", file=sys.stderr)
        return EXIT_BAD_INPUT
    run_dir = Path(argv[0])
    if not run_dir.is_dir():
        note(f"run directory '{run_dir}' does not exist or is not a directory")
        return EXIT_BAD_INPUT

    plotter = Plotter(run_dir)
    gr_file = next((run_dir / n for n in ("gr.tsv", "structure.tsv") if (run_dir / n).is_file()), None)
    jobs = [
        (run_dir / "log.tsv", plotter.log, "Z.png"),
        (run_dir / "correlations.tsv", plotter.correlations, "msd.png, c2.png, fself.png"),
        (gr_file or run_dir / "gr.tsv", plotter.gr, "gr.png"),
        (run_dir / "nematic.tsv", plotter.nematic, "s2.png"),
    ]
    if (run_dir / "gr_partial.tsv").is_file():  # mixtures only: no note when absent
        jobs.append((run_dir / "gr_partial.tsv", plotter.gr_partial, "gr_partial.png"))
    try:
        for path, plot, outputs in jobs:
            if not path.is_file():
                what = "gr.tsv or structure.tsv" if plot == plotter.gr else path.name
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
