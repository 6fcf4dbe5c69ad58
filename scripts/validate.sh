#!/usr/bin/env bash
# Long validations (not part of `make test`): 10^6 collisions of hard ellipsoids at phi = 0.5
# for X0 = 2 and X0 = 0.5 (N = 256, neighbour lists), with the independent Perram–Wertheim
# overlap test on every snapshot and on the final state. Results: docs/validation/ellipsoids.md.
# Usage: scripts/validate.sh [collisions]   (default 1000000; takes tens of minutes per state)
set -euo pipefail
cd "$(dirname "$0")/.."
HB=./build/apps/hardbody/hardbody
[ -x "$HB" ] || { echo "build first: make build" >&2; exit 1; }
coll=${1:-1000000}
out=docs/validation
mkdir -p "$out"
work=$(mktemp -d)
for spec in "2:1.0,0.5,0.5" "0.5:0.5,1.0,1.0"; do
  x0=${spec%%:*}; axes=${spec#*:}
  cat > "$work/e$x0.toml" <<TOML
[system]
particles = 256
packing_fraction = 0.5
seed = 7
[shape]
type = "ellipsoid"
semi_axes = [$axes]
[run]
equilibrate_time = 2.0
time = 1e9
max_collisions = $coll
[neighbors]
method = "nnl"
shell = 0.15
[output]
log_interval = 0.5
snapshot_interval = 0.5
[observables]
interval = 0.0
gr_interval = 0.0
TOML
  # the two states run side by side (two cores)
  ( "$HB" run "$work/e$x0.toml" --out "$work/run$x0" --quiet && \
    cp "$work/run$x0/summary.json" "$out/ellipsoids_X0_$x0.summary.json" ) &
done
wait
/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
rows = ["# Hard ellipsoids, 10^6 collisions at phi = 0.5 (scripts/validate.sh)", "",
        "| X0 | collisions | time | Z | Z error | energy drift | overlaps (final) | overlaps (all snapshots) | snapshots | min gap | solver fallbacks | tau_c (us) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|"]
for x0 in ["2", "0.5"]:
    s = json.load(open(f"{out}/ellipsoids_X0_{x0}.summary.json"))
    rows.append(f"| {x0} | {s['collisions']} | {s['time']:.2f} | {s['Z']:.4f} | {s['Z_error']:.4f} | {s['energy_drift']:.2e} | "
                f"{s['overlaps']} | {s['snapshot_overlaps']} | {s['trajectory_frames']} | {s['min_distance']:.2e} | {s['solver_fallbacks']} | {s['tau_c_us']:.0f} |")
open(f"{out}/ellipsoids.md", "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY
rm -rf "$work"
