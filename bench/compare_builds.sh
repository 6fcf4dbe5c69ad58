#!/usr/bin/env bash
# No-slowdown check: the cost per collision of the current tree against an older commit, both
# Release builds, measured in alternating runs (old, new, old, new, ...) in one session, since the
# machine is shared and noisy. Two state points:
#   hard spheres   N = 32000, phi = 0.45, cell lists (bench_hard_spheres), CPU ns per collision
#   ellipsoids     X0 = 2, phi = 0.5, N = 256, NNL (bench_rigid), CPU us per collision
# Usage: bench/compare_builds.sh OLD_COMMIT [ROUNDS=5] [instructions]
# The old commit is built in a detached worktree under ${TMPDIR:-/tmp}; the current tree must be
# built (make build). Prints one JSON line per run and a summary (medians, new/old ratios).
# With `instructions`, each build also runs once under valgrind's callgrind (smaller workloads:
# 3x10^5 sphere and 3000 ellipsoid collisions, whole process): instruction counts do not depend
# on the load of the machine, so their ratio resolves differences far below the timing noise.
set -euo pipefail
cd "$(dirname "$0")/.."
old=${1:?usage: bench/compare_builds.sh OLD_COMMIT [ROUNDS]}
rounds=${2:-5}
sha=$(git rev-parse --short "$old")
wt=${TMPDIR:-/tmp}/hardbody-old-$sha
new_hs=./build/bench/bench_hard_spheres new_rb=./build/bench/bench_rigid
[ -x "$new_hs" ] && [ -x "$new_rb" ] || { echo "build the current tree first: make build" >&2; exit 1; }
if [ ! -x "$wt/build/bench/bench_rigid" ]; then
  [ -d "$wt" ] || git worktree add --detach "$wt" "$old" >&2
  cmake -S "$wt" -B "$wt/build" -DCMAKE_BUILD_TYPE=Release -DHB_BUILD_TESTS=OFF -DHB_BUILD_PYTHON=OFF \
        -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
  cmake --build "$wt/build" -j "$(nproc)" --target bench_hard_spheres bench_rigid >&2
fi
old_hs=$wt/build/bench/bench_hard_spheres old_rb=$wt/build/bench/bench_rigid
log=$(mktemp)
for r in $(seq 1 "$rounds"); do
  for build in old new; do
    hs=${build}_hs rb=${build}_rb
    # hard spheres: 2e6 collisions measured after 20 per particle
    "${!hs}" 32000 0.45 2e6 640000 | sed "s/^{/{\"build\": \"$build\", \"round\": $r, \"point\": \"spheres\", /" | tee -a "$log"
    "${!rb}" shape=ellipsoid N=256 phi=0.5 X0=2 method=nnl collisions=20000 warmup=5000 check=0 \
      | sed "s/^{/{\"build\": \"$build\", \"round\": $r, \"point\": \"ellipsoids\", /" | tee -a "$log"
  done
done
/usr/bin/python3 - "$log" "$sha" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
def cost(r):
    return r["ns_per_collision"] if r["point"] == "spheres" else 1e3 * r["tau_c_us"]
print(f"\nnew (working tree) vs old ({sys.argv[2]}), CPU ns per collision, median of {max(r['round'] for r in rows)} alternating runs:")
for point in ["spheres", "ellipsoids"]:
    o = [cost(r) for r in rows if r["point"] == point and r["build"] == "old"]
    n = [cost(r) for r in rows if r["point"] == point and r["build"] == "new"]
    pairs = [b / a for a, b in zip(o, n)]
    print(json.dumps({"point": point, "old_median_ns": statistics.median(o), "new_median_ns": statistics.median(n),
                      "ratio_new_over_old": statistics.median(n) / statistics.median(o),
                      "ratio_per_round": [round(x, 4) for x in pairs]}))
PY
rm -f "$log"
if [ "${3:-}" = "instructions" ]; then
  echo; echo "instructions (callgrind, whole process):"
  for point in spheres ellipsoids; do
    for build in old new; do
      hs=${build}_hs rb=${build}_rb
      out=$(mktemp)
      if [ $point = spheres ]; then
        valgrind --tool=callgrind --callgrind-out-file="$out" "${!hs}" 32000 0.45 3e5 1e5 >/dev/null 2>&1
      else
        valgrind --tool=callgrind --callgrind-out-file="$out" "${!rb}" shape=ellipsoid N=256 phi=0.5 X0=2 \
          method=nnl collisions=3000 warmup=1000 check=0 >/dev/null 2>&1
      fi
      eval "ir_$build=$(sed -n 's/^summary: //p' "$out")"
      rm -f "$out"
    done
    /usr/bin/python3 -c "import json,sys; o,n=int(sys.argv[2]),int(sys.argv[3]); print(json.dumps({'point': sys.argv[1], 'old_instructions': o, 'new_instructions': n, 'ratio_new_over_old': n / o}))" \
      "$point" "$ir_old" "$ir_new"
  done
fi
