#!/usr/bin/env bash
# Side-by-side hard-sphere benchmark: hardbody against F. Smallenburg's EDMD, program `Single`
# (https://github.com/FSmallenburg/EDMD, MIT licence; hard spheres, one event per particle).
#
# Usage:
#   scripts/peer-bench.sh PATH_TO_EDMD_SOURCE [--quick] [--sizes "4000 32000 1000000"] [--rounds K]
#                         [--collisions C] [--out DIR] [--engine fast|generic]
#
#   PATH_TO_EDMD_SOURCE  the EDMD checkout (the directory holding Single/), or its Single/ directory.
#                        The script never changes it and nothing of it is copied into this
#                        repository: it is copied to a temporary directory, patched and built there.
#   --quick              1 round, sizes "4000 32000", C = 2e6 (unless given explicitly)
#   --sizes "..."        numbers of spheres (default "4000 32000 1000000")
#   --rounds K           alternating rounds per size (default 3)
#   --collisions C       collisions measured after equilibration (default 1e7)
#   --out DIR            where to write peer_hard_spheres.{md,jsonl} (default docs/benchmarks)
#   --engine E           hardbody's loop: fast (default, system/sphere_engine.hpp) or generic
#   PEER_COMMIT=...      (environment) the peer's commit, when the source is not a git work tree
#   PEER_BENCH_KEEP=1    (environment) keep the temporary directory (builds, logs) for inspection
#
# Getting the peer: git clone https://github.com/FSmallenburg/EDMD /tmp/EDMD
# Needs: bash, gcc, make, /usr/bin/python3 (standard library only), GNU time (/usr/bin/time;
# without it, CPU time comes from python's resource.getrusage on the child and max RSS from the
# child's VmHWM in /proc, polled every 20 ms).
# Our side must be built already (./build/bench/bench_hard_spheres); the script builds nothing here.
#
# What is measured (per N, phi = 0.45, monodisperse spheres of diameter 1, mass 1, kT = 1):
#   Collisions per CPU second (user + sys) in an NVE run after equilibration, no thermostat,
#   no output beyond a few progress lines; and memory per body = max RSS / N (bytes; it includes
#   the executable and libc, so at N = 4000 it is dominated by that fixed part: read the
#   N = 10^6 column).
#
# Same start for both codes: the FCC lattice of hardbody's fcc_lattice (src/setup/init.cpp:
# m = smallest integer with 4 m^3 >= N cells per edge, the first N sites in z, y, x, basis order,
# offset by a quarter cell, cubic box of side (N pi / (6 phi))^(1/3)). EDMD's own `fcc()` needs
# N = 4 m^3 exactly (10^6 is not), so the script writes this lattice to EDMD's input file format
# (init.sph: "N", "Lx Ly Lz", then "a x y z 0.5" per sphere) and EDMD reads it (its default
# initialconfig = 0, inputfilename "init.sph"). Velocities: each code's own Gaussian draw with
# kT = 1 exactly and zero total momentum (EDMD seed 1; hardbody seed 1).
#
# Peer settings, applied with sed to a COPY of Single/mdSingle.c (each substitution is checked):
#   const int usethermostat = 1   -> 0        (thermostat off: pure NVE)
#   double maxtime = 100          -> T1 or T2 (run length, in EDMD time units)
#   double writeinterval = 1      -> w        (progress line "Simtime: t, Collisions: c, ..." every w;
#                                              T1 and T2 are multiples of w)
#   makesnapshots = 0, initialconfig = 0, inputfilename = "init.sph" are its defaults (checked).
#   Everything else (event-list parameters, neighbour-list shell 1.5, MAXNEIGH 24) stays as shipped.
#   Built with its own Makefile (CFLAGS -Wall -Ofast -funroll-loops -march=native, gcc), `make -j1`.
#   Because maxtime is a source constant, there are two builds per N (short and long).
#   At the end it writes snapshot_end.sph (N lines) and, every w, one line to press.*.sph; both go
#   to the temporary run directory and are deleted.
#
# How the peer's CPU time per collision is measured: EDMD reports no timings, so each round runs
# it twice as whole processes, to T1 and to T2 > T1, with the same seed (the two trajectories are
# identical up to T1; the script checks the collision count at T1 in both). Then
#     rate_peer = (C(T2) - C(T1)) / (CPU(T2 run) - CPU(T1 run)),
# where C is the collision count of the progress line at t = T1 (short run) resp. T2 (long run)
# and CPU is the process's user + sys time from GNU time. Start-up (reading init.sph, cell and
# neighbour lists, first event calendar), the equilibration up to T1 and the final snapshot cancel.
# T1 is chosen for about 20 collisions per sphere (hardbody's equilibration is 20 N collisions)
# and T2 - T1 for C collisions, from the Carnahan-Starling collision rate at phi (about 14.2
# collisions per sphere per time unit at 0.45; T1 has a 25 % margin because the run from the
# lattice starts slower); the counts actually done are reported. T1 and T2 are multiples of w;
# w = min((T2 - T1) / 10, T1); each of the (T2 - T1) / w >= 10 progress lines inside the measured
# interval loops once over the N spheres (at most one sphere visit per ~20 collisions: negligible).
#
# Our side: ./build/bench/bench_hard_spheres N 0.45 C 20N 0 ENGINE (ENGINE = fast, the default:
# the dedicated hard-sphere loop with its default cages, SphereEngine::default_shell: 0.5 sigma
# up to N = 160000, 0.6 and 0.65 sigma beyond, the fastest for the size at phi = 0.45;
# --engine generic: the generic event loop with cell lists), which
# equilibrates 20 N collisions and then times C collisions in-process (CLOCK_PROCESS_CPUTIME_ID);
# its collisions_per_second is used. The whole process is also timed (GNU time) for its max RSS.
#
# Alternation: for each N, K rounds of [peer to T1, ours, peer to T2], whole processes one after
# another (never in parallel). Reported per N: the medians over rounds of each code's collisions
# per CPU second, the ratio ours / peer of those medians (> 1: hardbody is faster), the per-round
# values, and memory per body (largest max RSS over the rounds / N). Output: a Markdown table on
# stdout and in DIR/peer_hard_spheres.md, one JSON line per N in DIR/peer_hard_spheres.jsonl.
#
# Caveats: compiler flags differ (peer -Ofast -march=native as its Makefile says; hardbody Release
# -O3 -march=x86-64-v2, with GCC's inlining limits raised: CMakeLists.txt); the peer uses
# neighbour lists (shell 1.5) with a cell list; on a loaded machine single rounds vary by
# 10-20 %, use K >= 3.
set -euo pipefail

usage() { sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }

ROOT=$(cd "$(dirname "$0")/.." && pwd)
OURS="$ROOT/build/bench/bench_hard_spheres"
PHI=0.45
EQPP=20   # equilibration collisions per sphere
ENGINE=fast

[ $# -ge 1 ] || usage
SRC=$1; shift
quick=0; sizes=""; rounds=""; coll=""; outdir="$ROOT/docs/benchmarks"
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1; shift ;;
    --sizes) sizes=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --collisions) coll=$2; shift 2 ;;
    --out) outdir=$2; shift 2 ;;
    --engine) ENGINE=$2; shift 2 ;;
    -h|--help) usage ;;
    *) echo "unknown argument: $1" >&2; usage ;;
  esac
done
if [ "$quick" = 1 ]; then
  : "${sizes:=4000 32000}"; : "${rounds:=1}"; : "${coll:=2e6}"
else
  : "${sizes:=4000 32000 1000000}"; : "${rounds:=3}"; : "${coll:=1e7}"
fi

# --- the peer source --------------------------------------------------------------------------
if [ -f "$SRC/Single/mdSingle.c" ]; then SINGLE=$(cd "$SRC/Single" && pwd)
elif [ -f "$SRC/mdSingle.c" ]; then SINGLE=$(cd "$SRC" && pwd)
else echo "no Single/mdSingle.c under $SRC" >&2; exit 1; fi
for f in mdSingle.c mdSingle.h mt19937ar.c Makefile; do
  [ -f "$SINGLE/$f" ] || { echo "missing $SINGLE/$f" >&2; exit 1; }
done
commit=${PEER_COMMIT:-$(git -C "$SINGLE" rev-parse HEAD 2>/dev/null || echo unknown)}
dirty=""
if [ "$commit" != unknown ] && [ -z "${PEER_COMMIT:-}" ] \
   && [ -n "$(git -C "$SINGLE" status --porcelain -- . 2>/dev/null)" ]; then dirty=" (with local changes)"; fi

export ENGINE
[ -x "$OURS" ] || { echo "build hardbody first (missing $OURS)" >&2; exit 1; }
command -v gcc >/dev/null && command -v make >/dev/null || { echo "needs gcc and make" >&2; exit 1; }
PY=/usr/bin/python3
[ -x "$PY" ] || PY=$(command -v python3)

if [ -x /usr/bin/time ] && /usr/bin/time -f "%U" -o /dev/null true 2>/dev/null; then timer=gnu; else timer=python; fi

TMP=$(mktemp -d "${TMPDIR:-/tmp}/peer-bench.XXXXXX")
if [ -n "${PEER_BENCH_KEEP:-}" ]; then echo "keeping $TMP" >&2; else trap 'rm -rf "$TMP"' EXIT; fi
RUNS="$TMP/runs.tsv"   # kind N round T user sys maxrss_kB log
: > "$RUNS"

# timed KIND N ROUND T DIR LOG cmd...: run cmd in DIR, stdout+stderr to LOG, record CPU and RSS
timed() {
  local kind=$1 n=$2 round=$3 t=$4 dir=$5 log=$6; shift 6
  local tf="$TMP/time.out" rc=0
  if [ "$timer" = gnu ]; then
    (cd "$dir" && /usr/bin/time -f "%U %S %M" -o "$tf" "$@" > "$log" 2>&1) || rc=$?
  else
    # CPU: getrusage of the child. RSS: the child's VmHWM polled from /proc (ru_maxrss of a child
    # forked from python would include python's own resident set, inherited through the fork).
    (cd "$dir" && "$PY" -c '
import os, resource, subprocess, sys, time
p = subprocess.Popen(sys.argv[2:], stdout=open(sys.argv[1] + ".log", "w"), stderr=subprocess.STDOUT)
hwm = 0
while p.poll() is None:
    try:
        for line in open("/proc/%d/status" % p.pid):
            if line.startswith("VmHWM:"): hwm = max(hwm, int(line.split()[1]))
    except OSError:
        pass
    time.sleep(0.02)
u = resource.getrusage(resource.RUSAGE_CHILDREN)
open(sys.argv[1], "w").write("%.3f %.3f %d\n" % (u.ru_utime, u.ru_stime, hwm))
sys.exit(p.returncode)' "$tf" "$@") || rc=$?
    mv "$tf.log" "$log" 2>/dev/null || true
  fi
  if [ "$rc" != 0 ]; then
    echo "FAILED ($kind N=$n round $round, exit $rc): $*" >&2; tail -5 "$log" >&2; exit 1
  fi
  read -r u s m < "$tf"
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$kind" "$n" "$round" "$t" "$u" "$s" "$m" "$log" >> "$RUNS"
  printf '  %-10s N=%-8s round %s: user %s s, sys %s s, max RSS %s kB\n' "$kind" "$n" "$round" "$u" "$s" "$m" >&2
}

# patch_build DIR T W: copy Single/ to DIR, apply the settings, build with the peer's Makefile
patch_build() {
  local d=$1 t=$2 w=$3
  mkdir -p "$d"
  cp "$SINGLE/mdSingle.c" "$SINGLE/mdSingle.h" "$SINGLE/mt19937ar.c" "$SINGLE/Makefile" "$d/"
  local c="$d/mdSingle.c"
  sed -i -E \
    -e "s/^const int usethermostat = 1;/const int usethermostat = 0;/" \
    -e "s/^double maxtime = [0-9.eE+-]+;/double maxtime = $t;/" \
    -e "s/^double writeinterval = [0-9.eE+-]+;/double writeinterval = $w;/" "$c"
  grep -q "^const int usethermostat = 0;" "$c" || { echo "patch failed: usethermostat" >&2; exit 1; }
  grep -q "^double maxtime = $t;" "$c" || { echo "patch failed: maxtime" >&2; exit 1; }
  grep -q "^double writeinterval = $w;" "$c" || { echo "patch failed: writeinterval" >&2; exit 1; }
  grep -q "^int makesnapshots = 0;" "$c" || { echo "unexpected: makesnapshots != 0" >&2; exit 1; }
  grep -q "^int initialconfig = 0;" "$c" || { echo "unexpected: initialconfig != 0" >&2; exit 1; }
  grep -q '^char inputfilename\[100\] = "init.sph";' "$c" || { echo "unexpected: inputfilename" >&2; exit 1; }
  make -j1 -C "$d" > "$d/build.log" 2>&1 || { cat "$d/build.log" >&2; exit 1; }
  [ -x "$d/md" ] || { echo "peer build produced no md" >&2; exit 1; }
}

echo "peer: $SINGLE (commit $commit$dirty); ours: $OURS" >&2
echo "sizes: $sizes; rounds: $rounds; collisions: $coll; phi: $PHI; timer: $timer" >&2
PLAN="$TMP/plan.tsv"   # N T1 T2 w
: > "$PLAN"
for n in $sizes; do
  nd="$TMP/n$n"; mkdir -p "$nd/run"
  # run lengths: T1 = n1 w >= 1.25 EQPP / rate, T2 = T1 + k w ~ T1 + C / (rate N), k >= 10
  read -r t1 t2 w < <("$PY" - "$n" "$PHI" "$coll" "$EQPP" <<'PY'
import math, sys
n, eta, coll, eqpp = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
z = (1 + eta + eta**2 - eta**3) / (1 - eta)**3           # Carnahan-Starling
g = (z - 1) / (4 * eta)                                   # contact value
rho = 6 * eta / math.pi
rate = 0.5 * 4 * math.sqrt(math.pi) * rho * g             # collisions per sphere per time unit
teq = 1.25 * eqpp / rate                                  # 25 % margin: the lattice start is slower
dt = coll / (rate * n)
w = min(dt / 10, teq)                                     # progress interval
e = 10 ** (math.floor(math.log10(w)) - 2)
w = math.ceil(w / e - 1e-9) * e                           # rounded up to 3 digits
n1 = math.ceil(teq / w - 1e-9)                            # 1 when w >= teq
k = max(10, round(dt / w))                                # progress lines in the measured interval
print("%.10g %.10g %.10g" % (n1 * w, (n1 + k) * w, w))
PY
)
  printf '%s\t%s\t%s\t%s\n' "$n" "$t1" "$t2" "$w" >> "$PLAN"
  echo "N=$n: peer runs to T1=$t1 and T2=$t2 (progress every $w); building..." >&2
  # the shared FCC start, in EDMD's input format
  "$PY" - "$n" "$PHI" "$nd/run/init.sph" <<'PY'
import math, sys
n, phi, path = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
L = (n * math.pi / 6 / phi) ** (1 / 3)
m = 1
while 4 * m**3 < n: m += 1
a = L / m
basis = ((0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5))
out = ["%d" % n, "%.15g %.15g %.15g" % (L, L, L)]
k = 0
for z in range(m):
    for y in range(m):
        for x in range(m):
            for b in basis:
                if k == n: break
                out.append("a %.15g %.15g %.15g 0.5" % (a * (x + b[0] + 0.25), a * (y + b[1] + 0.25), a * (z + b[2] + 0.25)))
                k += 1
open(path, "w").write("\n".join(out) + "\n")
PY
  patch_build "$nd/short" "$t1" "$w"
  patch_build "$nd/long" "$t2" "$w"
  eq=$(( n * EQPP ))
  for r in $(seq 1 "$rounds"); do
    timed peer_short "$n" "$r" "$t1" "$nd/run" "$nd/peer_short.$r.log" "$nd/short/md"
    rm -f "$nd/run/snapshot_end.sph" "$nd"/run/press.*.sph
    timed ours "$n" "$r" 0 "$nd/run" "$nd/ours.$r.log" "$OURS" "$n" "$PHI" "$coll" "$eq" 0 "$ENGINE"
    timed peer_long "$n" "$r" "$t2" "$nd/run" "$nd/peer_long.$r.log" "$nd/long/md"
    rm -f "$nd/run/snapshot_end.sph" "$nd"/run/press.*.sph
  done
  rm -f "$nd/run/init.sph"
done

mkdir -p "$outdir"
cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1)
"$PY" - "$RUNS" "$PLAN" "$outdir" "$commit$dirty" "$SINGLE" "$coll" "$PHI" "$EQPP" "$rounds" "$timer" "${cpu:-unknown}" \
      "scripts/peer-bench.sh $SRC $( [ "$quick" = 1 ] && echo '--quick ' )--sizes \"$sizes\" --rounds $rounds --collisions $coll" <<'PY'
import json, re, statistics, sys, datetime, os
runs_f, plan_f, outdir, commit, single, coll, phi, eqpp, rounds, timer, cpu, cmdline = sys.argv[1:]
plan = {}
for line in open(plan_f):
    n, t1, t2, w = line.split()
    plan[int(n)] = (float(t1), float(t2), float(w))
runs = {}
for line in open(runs_f):
    kind, n, r, t, u, s, m, log = line.rstrip("\n").split("\t")
    runs[(kind, int(n), int(r))] = dict(cpu=float(u) + float(s), rss_kb=int(m), log=log)

prog = re.compile(r"Simtime: ([0-9.eE+-]+), Collisions: (\d+)")
def progress(log):
    return [(float(a), int(b)) for a, b in prog.findall(open(log).read())]

def at(lines, t, w):
    best = min(lines, key=lambda x: abs(x[0] - t))
    if abs(best[0] - t) > 0.01 * w:
        sys.exit("no progress line near t=%g in peer output" % t)
    return best[1]

med = statistics.median
rows = []
for n in sorted(plan):
    t1, t2, w = plan[n]
    pr, orr, prss, orss, pcoll, ocoll, oeng, warn = [], [], [], [], [], [], [], []
    for r in range(1, int(rounds) + 1):
        s, l, o = runs[("peer_short", n, r)], runs[("peer_long", n, r)], runs[("ours", n, r)]
        ls, ll = progress(s["log"]), progress(l["log"])
        c1, c1b, c2 = at(ls, t1, w), at(ll, t1, w), at(ll, t2, w)
        if c1 != c1b:
            warn.append("round %d: peer collisions at T1 differ between runs (%d, %d)" % (r, c1, c1b))
        dc, dt = c2 - c1, l["cpu"] - s["cpu"]
        pr.append(dc / dt if dt > 0 else float("nan"))
        pcoll.append(dc)
        js = [json.loads(x) for x in open(o["log"]) if x.startswith("{")]
        if not js:
            sys.exit("no JSON line from bench_hard_spheres: " + o["log"])
        orr.append(js[-1]["collisions_per_second"])
        ocoll.append(js[-1]["collisions"])
        if "bytes_per_body" in js[-1]:
            oeng.append(js[-1]["bytes_per_body"])
        prss.append(max(s["rss_kb"], l["rss_kb"]))
        orss.append(o["rss_kb"])
        pdt = dt; peq = c1
    ours_whole = [runs[("ours", n, r)]["cpu"] for r in range(1, int(rounds) + 1)]
    mp, mo = med(pr), med(orr)
    rows.append(dict(
        N=n, phi=float(phi), rounds=int(rounds), peer="FSmallenburg/EDMD Single", peer_commit=commit,
        peer_collisions_per_second=mp, ours_collisions_per_second=mo, ratio_ours_over_peer=mo / mp,
        peer_ns_per_collision=1e9 / mp, ours_ns_per_collision=1e9 / mo,
        peer_rounds=pr, ours_rounds=orr, peer_measured_collisions=pcoll, ours_measured_collisions=ocoll,
        peer_equil_collisions_per_sphere=peq / n, ours_equil_collisions_per_sphere=float(eqpp),
        peer_T1=t1, peer_T2=t2, peer_write_interval=w,
        peer_max_rss_kb=max(prss), ours_max_rss_kb=max(orss),
        peer_bytes_per_body=max(prss) * 1024 / n, ours_bytes_per_body=max(orss) * 1024 / n,
        ours_engine_bytes_per_body=max(oeng) if oeng else None,
        ours_whole_process_cpu_s=ours_whole, timer=timer, date=datetime.date.today().isoformat(), warnings=warn))

with open(os.path.join(outdir, "peer_hard_spheres.jsonl"), "w") as f:
    for r in rows:
        f.write(json.dumps(r) + "\n")

g = lambda x: "%.3g" % x
table = ["| N | peer coll/s | ours coll/s | ours / peer | peer ns/coll | ours ns/coll | peer B/body | ours B/body | peer per round | ours per round |",
         "|---|---|---|---|---|---|---|---|---|---|"]
for r in rows:
    table.append("| %d | %s | %s | %.2f | %.0f | %.0f | %.0f | %.0f | %s | %s |" % (
        r["N"], g(r["peer_collisions_per_second"]), g(r["ours_collisions_per_second"]),
        r["ratio_ours_over_peer"], r["peer_ns_per_collision"], r["ours_ns_per_collision"],
        r["peer_bytes_per_body"], r["ours_bytes_per_body"],
        ", ".join(map(g, r["peer_rounds"])), ", ".join(map(g, r["ours_rounds"]))))
warns = [w for r in rows for w in r["warnings"]]
doc = ["# Hard spheres against EDMD `Single` (phi = %s)" % phi, "",
       "Measured %s on %s, one process at a time (`%s` timer)." % (datetime.date.today().isoformat(), cpu, timer),
       "Peer: FSmallenburg/EDMD commit %s, `Single` built with its own Makefile "
       "(gcc -Wall -Ofast -funroll-loops -march=native); settings patched into a temporary copy: "
       "thermostat off (usethermostat = 0), maxtime = T1 / T2, writeinterval = w (T1, T2 multiples of w); "
       "start read from init.sph (hardbody's FCC lattice)." % commit,
       "Ours: `build/bench/bench_hard_spheres N %s C 20N 0 %s`, C = %s." % (phi, os.environ.get("ENGINE", "fast"), coll), "",
       "Command: `%s`" % cmdline, "",
       "Collisions per CPU second after equilibration (>= 20 collisions per sphere for both), median of %s "
       "alternating rounds. The peer's rate is (C(T2) - C(T1)) / (CPU(T2 run) - CPU(T1 run)) over two whole "
       "runs with the same seed, so its start-up and equilibration cancel; ours is timed in-process. "
       "ours / peer > 1: hardbody faster. B/body: max RSS / N (includes the fixed size of the process). "
       "Method in detail: the header of scripts/peer-bench.sh." % rounds, ""] + table + [""]
if warns:
    doc += ["Warnings:", ""] + ["- " + w for w in warns] + [""]
doc += ["| N | peer T1 | peer T2 | peer equil coll/sphere | peer measured coll (per round) |", "|---|---|---|---|---|"]
for r in rows:
    doc.append("| %d | %g | %g | %.1f | %s |" % (r["N"], r["peer_T1"], r["peer_T2"], r["peer_equil_collisions_per_sphere"],
                                                   ", ".join(map(str, r["peer_measured_collisions"]))))
open(os.path.join(outdir, "peer_hard_spheres.md"), "w").write("\n".join(doc) + "\n")
print("\n".join(table))
for w in warns:
    print("WARNING:", w)
print("wrote %s/peer_hard_spheres.{md,jsonl}" % outdir)
PY
