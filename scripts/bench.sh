#!/usr/bin/env bash
# Hard-sphere benchmark (issue 2): collisions per CPU second at N = 32000, phi = 0.45, and the
# cost per collision for N = 4000 ... 10^6. Writes docs/benchmarks/hard_spheres.{jsonl,md}.
# Usage: scripts/bench.sh [--quick]
set -euo pipefail
cd "$(dirname "$0")/.."
B=./build/bench/bench_hard_spheres
[ -x "$B" ] || { echo "build first: make build" >&2; exit 1; }
mkdir -p docs/benchmarks
out=docs/benchmarks/hard_spheres.jsonl
: > "$out.tmp"
quick=${1:-}
if [ "$quick" = "--quick" ]; then sizes="4000 32000"; coll=2e6; else sizes="4000 32000 256000 1000000"; coll=1e7; fi
for n in $sizes; do
  # equilibrate 20 collisions per particle (at least 1e6), then measure
  eq=$(( n * 20 > 1000000 ? n * 20 : 1000000 ))
  "$B" "$n" 0.45 "$coll" "$eq" | tee -a "$out.tmp"
done
mv "$out.tmp" "$out"
/usr/bin/python3 - "$out" <<'PY'
import json, sys, platform, subprocess
rows = [json.loads(l) for l in open(sys.argv[1])]
cpu = subprocess.run(["sh", "-c", "lscpu | grep 'Model name' | sed 's/.*: *//'"], capture_output=True, text=True).stdout.strip()
ref = next((r for r in rows if r["N"] == 4000), rows[0])
lines = ["# Hard-sphere benchmark", "", f"Machine: {cpu}, one core. Command: `scripts/bench.sh`.", "",
         "| N | phi | collisions | CPU s | collisions/s | ns/collision | cost vs N=4000 | cell crossings/coll | stale/coll |",
         "|---|---|---|---|---|---|---|---|---|"]
for r in rows:
    lines.append(f"| {r['N']} | {r['phi']} | {r['collisions']:.3g} | {r['cpu_seconds']:.2f} | {r['collisions_per_second']:.3g} | "
                 f"{r['ns_per_collision']:.0f} | {r['ns_per_collision']/ref['ns_per_collision']:.2f} | "
                 f"{r['cell_crossings_per_collision']:.3f} | {r['stale_per_collision']:.3f} |")
open("docs/benchmarks/hard_spheres.md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
