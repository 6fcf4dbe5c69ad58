#!/usr/bin/env bash
# The paper's performance study (sections 4 and 5) on this code: builds the benchmarks, runs
# every measurement (one process at a time, under nice) and writes CSV tables, PNG plots and a
# report that sets the findings next to the paper's.
#
# Usage: scripts/performance.sh [--quick] [--build DIR] [--out DIR] [--plot-only]
#   full run (~15-25 min CPU): docs/performance/ (raw.jsonl, meta.json, *.csv, *.png) and
#                              docs/performance.md
#   --quick (< 3 min):         fewer points and collisions, into build/performance-quick/ and
#                              build/performance-quick.md (not for committing)
#   --build DIR                the Release build to use (default build/); its bench targets are built
#   --out DIR                  output directory; the report goes to DIR.md
#   --plot-only                redo the tables, plots and report from DIR/raw.jsonl
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0; plot_only=0; build=build; out=
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --plot-only) plot_only=1 ;;
    --build) build=$2; shift ;;
    --out) out=$2; shift ;;
    *) echo "usage: scripts/performance.sh [--quick] [--build DIR] [--out DIR] [--plot-only]" >&2; exit 2 ;;
  esac
  shift
done
if [ -z "$out" ]; then
  if [ $quick = 1 ]; then out=build/performance-quick; else out=docs/performance; fi
fi
out=${out%/}
if [ $plot_only = 0 ]; then
  [ -f "$build/CMakeCache.txt" ] || { echo "no build in $build: run make build first" >&2; exit 1; }
  grep -q '^CMAKE_BUILD_TYPE:STRING=Release' "$build/CMakeCache.txt" ||
    { echo "$build is not a Release build" >&2; exit 1; }
  nice cmake --build "$build" -j2 --target bench_rigid bench_ratio >/dev/null
  /usr/bin/python3 scripts/performance.py --build "$build" --out "$out" $([ $quick = 1 ] && echo --quick)
fi
/usr/bin/python3 scripts/performance_plot.py "$out" "$out.md"
