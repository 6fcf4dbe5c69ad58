#!/usr/bin/env bash
# Long validations (not part of `make test`). Every run is `hardbody run`, which applies the
# independent overlap check (Perram–Wertheim for ellipsoids, surface sampling for superquadrics)
# to every snapshot and to the final state; the summaries are kept in docs/validation/ and the
# tables there are rebuilt from them.
#
# Usage: scripts/validate.sh [GROUP] [collisions]
#   ellipsoids      (default) 10^6 collisions of N = 256 ellipsoids at phi = 0.5, X0 = 2 and 0.5,
#                   NNL -> docs/validation/ellipsoids.md      (issue 4)
#   ellipsoids-045  10^6 collisions at phi = 0.45, X0 = 5 and 0.2, NNL, grown from phi0 = 0.1
#                   -> docs/validation/ellipsoids_045.md      (issue 4)
#   superquadrics   N = 512, phi = 0.256, exponents [2, 2, p] (the paper's section 5: n = m = 2),
#                   smallest semi-axis 0.8, I = 1, X0 = 2 and 0.5, NNL and cells
#                   -> docs/validation/superquadrics.md       (issue 5)
#   sq-taus         one short superquadric run per p (X0 = 2, NNL) to measure tau_c first
#   sq-vs-ellipsoid ellipsoid vs superquadric [2, 2, 2] at the superquadric state point (Z)
#   tops            10^6 collisions of N = 256 triaxial ellipsoids [1.5, 1, 0.6] (asymmetric tops,
#                   uniform-density inertia) at phi = 0.40, NNL -> docs/validation/runs/tops.summary.json
#                   (issue 11: per-axis rotational temperatures, energy drift)
#   walls           the wall and container contact-time tests on 10,000 random bodies per shape
#                   (HB_TEST_SCALE=10 of build/tests/locals/test_locals; make test runs 1000) (issue 12)
#   tables          only rebuild the .md tables from the stored summaries
#   slurm           campaigns on a one-node Slurm cluster (scripts/test-slurm-campaign.sh; issue 14)
#   `scripts/validate.sh 1000000` (a number first) is the old form: the ellipsoids group.
# Environment: HB (binary, default build/apps/hardbody/hardbody), WORK (run directories, default
#   /tmp/hardbody-validate; GSD/log outputs stay there), SQ_P ("2 4 8 12 16"), SQ_X0 ("2 0.5"),
#   HB_BUILD (label of the binary's source, stored in each summary as "build"; default HEAD),
#   SQ_METHODS ("nnl cells"), SQ_SNAP (superquadrics group: time between the snapshots that
#   get the overlap check, default 2.0; each check costs ~1 s of CPU at N = 512), E045 ("X0:N:a,b,c ..."), NICE (default 10), DEADLINE (epoch
#   seconds: no run starts after it). Runs go one at a time. A failed run (exit 3)
#   does not stop the group: its command and the last lines of stderr (the reproducer) go to
#   docs/validation/failures.md.
set -uo pipefail
cd "${VALIDATE_ROOT:-$(dirname "$0")/..}"   # VALIDATE_ROOT: run a copy of this script
HB=${HB:-./build/apps/hardbody/hardbody}
[ -x "$HB" ] || { echo "build first: make build (or set HB)" >&2; exit 1; }
group=ellipsoids
case "${1:-}" in
  [0-9]*) ;;
  "") ;;
  *) group=$1; shift ;;
esac
coll=${1:-1000000}
out=docs/validation
work=${WORK:-/tmp/hardbody-validate}
nice_level=${NICE:-10}
mkdir -p "$out/runs" "$work"

# sections NEIGHBOURS LOG_INTERVAL SNAPSHOT_INTERVAL: the start (grown from phi0 = 0.1), the run
# (2 time units of equilibration, then $coll collisions), neighbours, solver and output
sections() {
  cat <<TOML
[init]
method = "grow"
phi0 = 0.1
growth_rate = 0.05
[run]
equilibrate_time = 2.0
time = 1e9
max_collisions = $coll
[neighbors]
method = "$1"
shell = 0.15
[solver]
eps_d = 1e-5
[output]
log_interval = $2
snapshot_interval = $3
[observables]
interval = 0.0
gr_interval = 0.0
TOML
}

# ellipsoid_config NAME SEMI_AXES PHI N
ellipsoid_config() {
  { cat <<TOML
[system]
particles = $4
packing_fraction = $3
seed = 7
[shape]
type = "ellipsoid"
semi_axes = [$2]
TOML
    sections nnl 0.5 0.5; } > "$work/$1.toml"
}

# superquadric_config NAME X0 P METHOD SNAPSHOT_INTERVAL: the paper's state (section 5)
superquadric_config() {
  local axes
  if [ "$2" = 2 ]; then axes="1.6, 0.8, 0.8"; else axes="0.8, 1.6, 1.6"; fi
  { cat <<TOML
[system]
particles = 512
packing_fraction = 0.256
seed = ${SEED:-1}
[shape]
type = "superquadric"
semi_axes = [$axes]
exponents = [2.0, 2.0, $3]
inertia = 1.0
TOML
    sections "$4" 1.0 "$5"; } > "$work/$1.toml"
}

# run NAME: runs $work/NAME.toml into $work/NAME, keeps the summary as $out/runs/NAME.summary.json
run() {
  local name=$1 rc
  if [ -n "${DEADLINE:-}" ] && [ "$(date +%s)" -ge "$DEADLINE" ]; then
    echo "$name: not started (past DEADLINE)" >&2; return 1
  fi
  rm -rf "$work/$name"
  echo "== $name ($(date -u +%H:%M:%S))" >&2
  nice -n "$nice_level" "$HB" run "$work/$name.toml" --out "$work/$name" --overwrite --quiet \
    2> "$work/$name.stderr"
  rc=$?
  if [ $rc -eq 0 ]; then
    # the summary, with the build that ran it (HB_BUILD, e.g. a commit; default: HEAD's)
    /usr/bin/python3 - "$work/$name/summary.json" "$out/runs/$name.summary.json" \
      "${HB_BUILD:-$(git rev-parse --short HEAD 2>/dev/null || echo unknown)}" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["build"] = sys.argv[3]
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY
  else
    echo "$name: exit $rc" >&2
    { echo "## $name: exit $rc ($(date -u +%F))"; echo
      echo "build: ${HB_BUILD:-$(git rev-parse --short HEAD 2>/dev/null || echo unknown)}"
      [ -f "$work/$name/log.tsv.part" ] && tail -n 1 "$work/$name/log.tsv.part" |
        awk -F'\t' '{printf "reached: collisions %d, time %s\n", $2, $1}'
      echo; echo '```'
      echo "$HB run $work/$name.toml --out $work/$name"; tail -n 20 "$work/$name.stderr"
      echo '```'; echo; } >> "$out/failures.md"
  fi
}

case "$group" in
  ellipsoids)
    ellipsoid_config e2 "1.0, 0.5, 0.5" 0.5 256 && run e2 && \
      cp "$out/runs/e2.summary.json" "$out/ellipsoids_X0_2.summary.json"
    ellipsoid_config e0.5 "0.5, 1.0, 1.0" 0.5 256 && run e0.5 && \
      cp "$out/runs/e0.5.summary.json" "$out/ellipsoids_X0_0.5.summary.json" ;;
  ellipsoids-045)
    # N = 256 for X0 = 0.2; X0 = 5 needs N >= 400 (at N = 256 the grown start's box is 8.35 on its
    # short side, less than two body lengths, 10, and `hardbody run` refuses it)
    for spec in ${E045:-0.2:256:0.5,2.5,2.5 5:400:2.5,0.5,0.5}; do
      x0=${spec%%:*}; rest=${spec#*:}; name=e045_X0_$x0
      ellipsoid_config "$name" "${rest#*:}" 0.45 "${rest%%:*}" && run "$name"
    done ;;
  superquadrics)
    for x0 in ${SQ_X0:-2 0.5}; do
      for m in ${SQ_METHODS:-nnl cells}; do
        for p in ${SQ_P:-2 4 8 12 16}; do
          name=sq_X0_${x0}_p${p}_${m}
          superquadric_config "$name" "$x0" "$p" "$m" "${SQ_SNAP:-2.0}" && run "$name"
        done
      done
    done ;;
  sq-taus)
    coll=${1:-20000}
    for p in ${SQ_P:-2 4 8 12 16}; do
      superquadric_config "sqtau_p$p" 2 "$p" nnl 1.0 && run "sqtau_p$p"
    done ;;
  sq-vs-ellipsoid)
    # the ellipsoid at the state of sq_X0_2_p2_nnl (superquadrics group: N = 512, phi = 0.256,
    # semi-axes 1.6, 0.8, 0.8, I = 1, same seed, start and collision count); SQ_X0 = 0.5 for
    # oblate; SEEDS ("1"): other seeds run a further pair, superquadric [2, 2, 2] and ellipsoid
    for x0 in ${SQ_X0:-2}; do
      for seed in ${SEEDS:-1}; do
        if [ "$seed" = 1 ]; then sfx=""; else
          sfx=_s$seed
          SEED=$seed superquadric_config "sqe_sq_X0_$x0$sfx" "$x0" 2.0 nnl 2.0 && run "sqe_sq_X0_$x0$sfx"
        fi
        SEED=$seed superquadric_config "sqe_el_X0_$x0$sfx" "$x0" 2.0 nnl 2.0 && \
          sed -i -e 's/^type = "superquadric"/type = "ellipsoid"/' -e '/^exponents/d' \
            "$work/sqe_el_X0_$x0$sfx.toml" && run "sqe_el_X0_$x0$sfx"
      done
    done ;;
  tops)
    # issue 11: asymmetric tops (triaxial [1.5, 1, 0.6], uniform-density inertia) at phi = 0.40:
    # equipartition over the principal axes, energy drift over 10^6 collisions, no overlap
    { cat <<TOML
[system]
packing_fraction = 0.40
seed = 3
[[species]]
name = "T"
count = 256
shape = { type = "ellipsoid", semi_axes = [1.5, 1.0, 0.6] }
TOML
      sections nnl 2.0 50.0; } > "$work/tops.toml" && run tops ;;
  slurm)
    # issue 14: campaigns as Slurm job arrays on a one-node cluster (scripts/slurm-local.sh starts
    # munge, slurmctld, slurmd): scancel --signal=TERM and a time limit, requeued and resumed,
    # results identical to the local executor's (scripts/test-slurm-campaign.sh; ~5 minutes)
    HB="$HB" exec scripts/test-slurm-campaign.sh ;;
  walls)
    # issue 12: contact times against a slow conservative advancement, 10,000 bodies per shape
    # (planar walls already run 10,000 in make test; the container's truth is slower: ~15 CPU min)
    t=$(dirname "$HB")/../../tests/locals/test_locals
    HB_TEST_SCALE=10 exec "$t" --gtest_filter='SphericalContainer.*ContactTime*' ;;
  tables) ;;
  *) echo "unknown group '$group' (ellipsoids, ellipsoids-045, superquadrics, sq-taus, sq-vs-ellipsoid, tops, walls, slurm, tables)" >&2
     exit 2 ;;
esac

# the tables, rebuilt from every summary present
/usr/bin/python3 - "$out" "$work" <<'PY'
import glob, json, math, os, re, sys
out, work = sys.argv[1], sys.argv[2]

def late(name):
    """Z over the second half of the measured run (mean and standard error of the log blocks)
    and the nematic order S2 (mean over the run, last sample), from the run directory when it
    is still there; kept in runs/NAME.extra.json."""
    keep = f"{out}/runs/{name}.extra.json"
    log, nem = f"{work}/{name}/log.tsv", f"{work}/{name}/nematic.tsv"
    if os.path.exists(log):
        rows = [l.split("\t") for l in open(log).read().split("\n")[1:] if l.strip()]
        t_end = float(rows[-1][0])
        z = [float(r[2]) for r in rows if float(r[0]) > t_end / 2]
        m = sum(z) / len(z)
        e = math.sqrt(sum((x - m) ** 2 for x in z) / (len(z) - 1) / len(z)) if len(z) > 1 else 0.0
        extra = {"Z_second_half": m, "Z_second_half_error": e, "Z_second_half_blocks": len(z)}
        if os.path.exists(nem):
            lines = open(nem).read().split("\n")
            head = dict(kv.split("=") for kv in lines[1].lstrip("# ").split())
            data = [l.split("\t") for l in lines[3:] if l.strip()]
            extra.update(S2_mean=float(head["S2_mean"]), S2_first=float(data[0][1]), S2_last=float(data[-1][1]))
        json.dump(extra, open(keep, "w"), indent=1)
    return json.load(open(keep)) if os.path.exists(keep) else {}

def load(path):
    return json.load(open(path)) if os.path.exists(path) else None

def fb(s):
    v = s["solver"]
    return (f"{s['solver_fallbacks']} (dist {v['distance_fallbacks']}, coll-dist "
            f"{v['collision_distance_fallbacks']}, contact {v['contact_fallbacks']})")

def failed(prefix):
    """Failures in failures.md of runs named PREFIX*, in file order: exit, message, build, and how
    far the run got (the `reached:` line run() writes from the run's log at the time of failure)."""
    res, text = {}, open(f"{out}/failures.md").read() if os.path.exists(f"{out}/failures.md") else ""
    for part in text.split("## ")[1:]:
        head, body = part.split("\n", 1)
        name, rc = head.split(": exit ")
        if not name.startswith(prefix):
            continue
        lines = body.split("\n")
        msg = [l for l in lines if l.startswith("hardbody:")]
        build = [l[len("build: "):] for l in lines if l.startswith("build: ")]
        f = {"exit": int(rc.split()[0]), "message": msg[-1] if msg else "",
             "build": build[0] if build else "session 2"}
        for l in lines:
            m = re.match(r"reached: collisions (\d+), time ([0-9.eE+-]+)", l)
            if m:
                f.update(collisions=int(m.group(1)), time=float(m.group(2)))
        res.setdefault(name, []).append(f)
    return res

def write(name, lines):
    open(f"{out}/{name}", "w").write("\n".join(lines) + "\n")

# ellipsoids, phi = 0.5 (the original group)
rows = ["# Hard ellipsoids, 10^6 collisions at phi = 0.5 (scripts/validate.sh ellipsoids)", "",
        "| X0 | collisions | time | Z | Z error | energy drift | overlaps (final) | overlaps (all snapshots) | snapshots | min gap | solver fallbacks | tau_c (us) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|"]
for x0 in ["2", "0.5"]:
    s = load(f"{out}/ellipsoids_X0_{x0}.summary.json")
    if s:
        rows.append(f"| {x0} | {s['collisions']} | {s['time']:.2f} | {s['Z']:.4f} | {s['Z_error']:.4f} | {s['energy_drift']:.2e} | "
                    f"{s['overlaps']} | {s['snapshot_overlaps']} | {s['trajectory_frames']} | {s['min_distance']:.2e} | {s['solver_fallbacks']} | {s['tau_c_us']:.0f} |")
write("ellipsoids.md", rows)

# ellipsoids, phi = 0.45
rows = ["# Hard ellipsoids at phi = 0.45, X0 = 5 and 0.2 (scripts/validate.sh ellipsoids-045)", "",
        "Grown from phi0 = 0.1 at growth rate 0.05 (`[init] method = \"grow\"`), equilibrated for 2 time",
        "units, then measured for `collisions`; NNL with shell 0.15. `overlaps` is the Perram–Wertheim",
        "check of the final state, `snapshot overlaps` the same check summed over all `snapshots`.",
        "Summaries: runs/e045_X0_*.summary.json. X0 = 5 runs at N = 400: at N = 256 the grown",
        "start's box is 8.35 on its short side, less than two body lengths (10), and `hardbody run`",
        "refuses it (exit 2, failures.md). Growth wall seconds were measured on a shared, loaded machine.", "",
        "`Z` is over the whole measured run, `Z (2nd half)` over its second half (log blocks of 0.5),",
        "`S2` the nematic order parameter (first / mean / last sample): the isotropic state left by the",
        "growth orders into a nematic during the run at these elongations, and Z falls with it, so the",
        "whole-run Z is not an equilibrium value and its block error is inflated by the drift.", "",
        "| X0 | N | semi-axes | collisions | sim. time | Z | Z (2nd half) | S2 | energy drift | overlaps (final) | snapshot overlaps | snapshots | min gap (final / snapshots) | solver fallbacks | CPU s | tau_c (us) | growth: time / collisions / wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for x0 in ["5", "0.2"]:
    s = load(f"{out}/runs/e045_X0_{x0}.summary.json")
    if not s:
        continue
    g, x = s["init"], late(f"e045_X0_{x0}")
    zl = f"{x['Z_second_half']:.3f} ± {x['Z_second_half_error']:.3f}" if x else "-"
    s2 = f"{x['S2_first']:.2f} / {x['S2_mean']:.2f} / {x['S2_last']:.2f}" if "S2_mean" in x else "-"
    rows.append(f"| {x0} | {s['particles']} | {', '.join(f'{a:g}' for a in s['shape']['semi_axes'])} | {s['collisions']} | "
                f"{s['time']:.1f} | {s['Z']:.3f} ± {s['Z_error']:.3f} | {zl} | {s2} | {s['energy_drift']:.1e} | {s['overlaps']} | "
                f"{s['snapshot_overlaps']} | {s['trajectory_frames']} | {s['min_distance']:.1e} / {s['snapshot_min_distance']:.1e} | "
                f"{fb(s)} | {s['cpu_seconds']:.0f} | {s['tau_c_us']:.0f} | "
                f"{g.get('growth_time', 0):.2f} / {g.get('growth_collisions', 0)} / {g.get('growth_wall_seconds', 0):.0f} |")
write("ellipsoids_045.md", rows)

# superquadrics
def sqrows(pattern):
    runs = []
    for f in glob.glob(f"{out}/runs/{pattern}.summary.json"):
        s = json.load(open(f))
        runs.append((s, os.path.basename(f)))
    order = {"nnl": 0, "cells": 1}
    runs.sort(key=lambda r: (-r[0]["shape"]["semi_axes"][0], order[r[0]["neighbors"]], r[0]["shape"]["exponents"][2]))
    return runs

rows = ["# Hard superquadrics at the paper's state point (scripts/validate.sh superquadrics)", "",
        "|x/a|^2 + |y/b|^2 + |z/c|^p <= 1 (the paper's section 5: n = m = 2, p varied), N = 512,",
        "phi = 0.256, smallest semi-axis 0.8 (X0 = 2: a = 1.6, b = c = 0.8; X0 = 0.5: a = 0.8,",
        "b = c = 1.6), I = 1, grown from phi0 = 0.1, equilibrated for 2 time units, snapshots every 2",
        "or 10 time units (SQ_SNAP; their number is in `snapshots`). `overlaps` is the surface-sampling",
        "check (observers/overlap_sampling) of the final state, `snapshot overlaps` the same check",
        "summed over all `snapshots`; drift is the relative kinetic-energy change over the measured",
        "run; fallbacks are the solver's (distance / collision-distance / contact-time). `build` is",
        "the source the binary was built from (runs of different builds are mixed in this table; a",
        "run without the field predates it: session 2's build). tau_c is CPU time per collision on",
        "the shared 2-core machine while other runs were going (not a benchmark: see",
        "docs/performance.md). Summaries: runs/sq_*.summary.json.", "",
        "The issue asks for 10^6 collisions per run; the count is in `collisions`. A missing",
        "(p, X0, method) row was not run or failed (next table).", "",
        "| p | X0 | method | collisions | overlaps (final) | snapshot overlaps | snapshots | min gap (final / snapshots) | energy drift | fallbacks | Z | tau_c (us) | CPU s | build |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for s, _ in sqrows("sq_X0_*"):
    a = s["shape"]["semi_axes"]
    rows.append(f"| {s['shape']['exponents'][2]:g} | {a[0] / a[1]:g} | {s['neighbors']} | {s['collisions']} | {s['overlaps']} | "
                f"{s['snapshot_overlaps']} | {s['trajectory_frames']} | {s['min_distance']:.1e} / {s['snapshot_min_distance']:.1e} | "
                f"{s['energy_drift']:.1e} | {fb(s)} | {s['Z']:.4f} ± {s['Z_error']:.4f} | {s['tau_c_us']:.0f} | {s['cpu_seconds']:.0f} | {s.get('build', 'session 2')} |")
rows += ["", "## Exponents [2, 2, 2] against the ellipsoid (same state, seed, start and collision count)", "",
         "| X0 | seed | shape | collisions | Z | collision rate | tau_c (us) |", "|---|---|---|---|---|---|---|"]
for x0 in ["2", "0.5"]:
    pairs = [(f"sq_X0_{x0}_p2_nnl", f"sqe_el_X0_{x0}")]
    for f in sorted(glob.glob(f"{out}/runs/sqe_sq_X0_{x0}_s*.summary.json")):
        sfx = f.split(f"sqe_sq_X0_{x0}")[1].split(".summary")[0]
        pairs.append((f"sqe_sq_X0_{x0}{sfx}", f"sqe_el_X0_{x0}{sfx}"))
    for names in pairs:
        for name, label in zip(names, ["superquadric [2, 2, 2]", "ellipsoid"]):
            s = load(f"{out}/runs/{name}.summary.json")
            if s:
                rows.append(f"| {x0} | {s['seed']} | {label} | {s['collisions']} | {s['Z']:.4f} ± {s['Z_error']:.4f} | "
                            f"{s['collision_rate']:.3f} ± {s['collision_rate_error']:.3f} | {s['tau_c_us']:.0f} |")
    # all seeds pooled (independent runs: inverse-variance mean)
    got = [[load(f"{out}/runs/{n}.summary.json") for n in names] for names in pairs]
    got = [g for g in got if all(g)]
    if len(got) > 1:
        pooled = []
        for k, label in enumerate(["superquadric [2, 2, 2]", "ellipsoid"]):
            w = [1 / g[k]["Z_error"] ** 2 for g in got]
            z = sum(wi * g[k]["Z"] for wi, g in zip(w, got)) / sum(w)
            pooled.append((z, sum(w) ** -0.5))
            rows.append(f"| {x0} | pooled | {label} | {sum(g[k]['collisions'] for g in got)} | {z:.4f} ± {pooled[-1][1]:.4f} | | |")
        d, e = pooled[0][0] - pooled[1][0], math.hypot(pooled[0][1], pooled[1][1])
        rows.append(f"| {x0} | pooled | difference | | {d:+.4f} ± {e:.4f} ({d / e:+.1f} sigma) | | |")
fails = failed("sq")
if fails:
    rows += ["", "## Failed runs (exit 3; reproducer: `hardbody run CONFIG --out DIR --resume` from the checkpoint the run wrote, details in failures.md)", "",
             "Every failure is listed with the build that failed; `later` says whether a later build",
             "completed the same run (then it is in the table above).", "",
             "| run | build | exit | collisions reached (measured) | sim. time reached | later | message |", "|---|---|---|---|---|---|---|"]
    for name, fl in sorted(fails.items()):
        done = load(f"{out}/runs/{name}.summary.json") if os.path.exists(f"{out}/runs/{name}.summary.json") else None
        for f in fl:
            later = (f"completed with {done.get('build', 'session 2')}" if done and done.get("build", "session 2") != f["build"] else "-")
            rows.append(f"| {name} | {f['build']} | {f['exit']} | {f.get('collisions', '-')} | {f.get('time', '-')} | {later} | {f['message'][:300]} |")
taus = sqrows("sqtau_p*")
if taus:
    rows += ["", "## Short runs for tau_c (scripts/validate.sh sq-taus: X0 = 2, NNL, snapshots every time unit)", "",
             "| p | collisions | tau_c (us) | overlaps | snapshot overlaps | snapshots | fallbacks |", "|---|---|---|---|---|---|---|"]
    for s, _ in taus:
        rows.append(f"| {s['shape']['exponents'][2]:g} | {s['collisions']} | {s['tau_c_us']:.0f} | {s['overlaps']} | "
                    f"{s['snapshot_overlaps']} | {s['trajectory_frames']} | {fb(s)} |")
write("superquadrics.md", rows)
PY
