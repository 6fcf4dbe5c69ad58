#!/usr/bin/env python3
"""Are two campaigns' runs the same simulations? ``campaign_compare.py OUT_A OUT_B``

For every run directory OUT_A/runs/NAME (and the same NAME under OUT_B) the final states must be
identical bit for bit: every chunk of checkpoint.gsd but the driver's bookkeeping (it holds CPU
and wall seconds), every frame of trajectory.gsd, log.tsv, and summary.json without the keys
that measure the machine (seconds, rates per second, per-session counters). Used by
tests/cli/test_campaign.py (interrupted against uninterrupted campaigns) and
scripts/test-slurm-campaign.sh (Slurm against local). Prints one line per difference; exit 0
when there is none, 1 otherwise, 2 when a directory is missing.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

# summary.json keys that depend on the machine or on how often the run was resumed
MACHINE_KEYS = {"wall_seconds", "cpu_seconds", "collisions_per_second", "tau_c_us",
                "solver", "snapshot_overlaps", "snapshot_min_distance"}  # the last three: per session


def _chunks(path: Path, skip=()) -> list[dict]:
    import gsd.fl
    frames = []
    with gsd.fl.open(str(path), "rb") as f:
        names = sorted(f.find_matching_chunk_names(""))
        for i in range(f.nframes):
            frames.append({n: f.read_chunk(i, n).tobytes() for n in names
                           if n not in skip and f.chunk_exists(i, n)})
    return frames


def compare_run(a: Path, b: Path) -> list[str]:
    diffs = []
    for f in ["summary.json", "log.tsv", "checkpoint.gsd", "trajectory.gsd"]:
        if (a / f).exists() != (b / f).exists():
            diffs.append(f"{f}: present in only one of them")
    if diffs:
        return diffs
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
    for k in sorted(set(sa) | set(sb)):
        if k not in MACHINE_KEYS and sa.get(k) != sb.get(k):
            diffs.append(f"summary.json: {k}: {sa.get(k)!r} != {sb.get(k)!r}")
    if (a / "log.tsv").read_bytes() != (b / "log.tsv").read_bytes():
        diffs.append("log.tsv differs")
    ca, cb = (_chunks(d / "checkpoint.gsd", skip={"log/hardbody/driver"}) for d in (a, b))
    if ca != cb:
        bad = sorted({n for fa, fb in zip(ca, cb) for n in set(fa) | set(fb) if fa.get(n) != fb.get(n)})
        diffs.append(f"checkpoint.gsd differs: {', '.join(bad) or 'frame count'}")
    if (a / "trajectory.gsd").exists():
        ta, tb = (_chunks(d / "trajectory.gsd") for d in (a, b))
        if ta != tb:
            diffs.append(f"trajectory.gsd differs ({len(ta)} and {len(tb)} frames)")
    return diffs


def compare(out_a, out_b) -> list[str]:
    """Differences between the runs of two campaign directories (empty: identical)."""
    ra, rb = Path(out_a) / "runs", Path(out_b) / "runs"
    names_a = sorted(p.name for p in ra.iterdir() if p.is_dir())
    names_b = sorted(p.name for p in rb.iterdir() if p.is_dir())
    diffs = [f"runs only in {out_a}: {n}" for n in sorted(set(names_a) - set(names_b))]
    diffs += [f"runs only in {out_b}: {n}" for n in sorted(set(names_b) - set(names_a))]
    for n in sorted(set(names_a) & set(names_b)):
        diffs += [f"{n}: {d}" for d in compare_run(ra / n, rb / n)]
    return diffs


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    for d in argv:
        if not (Path(d) / "runs").is_dir():
            print(f"campaign_compare: {d}/runs: no such directory", file=sys.stderr)
            return 2
    diffs = compare(*argv)
    for d in diffs:
        print(d)
    if not diffs:
        print(f"identical: every run of {argv[0]} and {argv[1]}")
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
