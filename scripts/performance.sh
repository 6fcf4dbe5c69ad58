#!/usr/bin/env bash
# The paper's performance study (sections 4 and 5) on this code: builds the benchmarks, runs
# every measurement (one process at a time, under nice) and writes CSV tables, PNG plots and a
# report that sets the findings next to the paper's.
#
# Usage: scripts/performance.sh [--quick] [--build DIR] [--out DIR] [--plot-only] [--only STUDIES]
#   full run (~15-25 min CPU): docs/performance/ (raw.jsonl, meta.json, *.csv, *.png) and
#                              docs/performance.md
#   --quick (< 3 min):         fewer points and collisions, into build/performance-quick/ and
#                              build/performance-quick.md (not for committing)
#   --build DIR                the Release build to use (default build/); its bench targets are built
#   --out DIR                  output directory; the report goes to DIR.md
#   --plot-only                redo the tables, plots and report from DIR/raw.jsonl
#   --only STUDIES             partial re-run: only the studies whose names start with one of the
#                              comma-separated prefixes (a, b, c, d, e1-e4, f, f_long, f_ratio; "f" is
#                              f, f_long and f_ratio, "e" is e1-e4), plus the perf profile if the list
#                              holds "profile". Their rows replace those of DIR/raw.jsonl (which must
#                              exist, from a run of the same mode), each stamped with the source
#                              commit and date; DIR/meta.json keeps the original run and lists the
#                              re-run under "updates"; the report says which sections were re-measured.
#                              E.g. scripts/performance.sh --only f --build build-sq
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: scripts/performance.sh [--quick] [--build DIR] [--out DIR] [--plot-only] [--only STUDIES]"
quick=0; plot_only=0; build=build; out=; only=
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --plot-only) plot_only=1 ;;
    --build) build=$2; shift ;;
    --out) out=$2; shift ;;
    --only) only=${2-}
            case "$only" in ""|-*) echo "--only needs a list of studies" >&2; echo "$usage" >&2; exit 2 ;; esac
            shift ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
  shift
done
if [ -z "$out" ]; then
  if [ $quick = 1 ]; then out=build/performance-quick; else out=docs/performance; fi
fi
out=${out%/}
if [ -n "$only" ]; then
  [ $plot_only = 0 ] || { echo "--only and --plot-only exclude each other" >&2; exit 2; }
  [ -f "$out/raw.jsonl" ] || { echo "--only merges into an earlier run, but $out/raw.jsonl does not exist" >&2; exit 2; }
  # check the study list and the mode of $out before building anything
  /usr/bin/python3 scripts/performance.py --out "$out" --only "$only" --dry-run $([ $quick = 1 ] && echo --quick) \
    >/dev/null || exit 2
fi
if [ $plot_only = 0 ]; then
  [ -f "$build/CMakeCache.txt" ] || { echo "no build in $build: run make build first" >&2; exit 1; }
  grep -q '^CMAKE_BUILD_TYPE:STRING=Release' "$build/CMakeCache.txt" ||
    { echo "$build is not a Release build" >&2; exit 1; }
  nice cmake --build "$build" -j2 --target bench_rigid bench_ratio >/dev/null
  args=(--build "$build" --out "$out")
  [ $quick = 1 ] && args+=(--quick)
  [ -n "$only" ] && args+=(--only "$only")
  /usr/bin/python3 scripts/performance.py "${args[@]}"
fi
/usr/bin/python3 scripts/performance_plot.py "$out" "$out.md"
