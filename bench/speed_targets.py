#!/usr/bin/python3
"""Every speed target of issue 15, measured in one session and set against its threshold.

Usage: bench/speed_targets.py [--quick] [--rounds K] [--build DIR] [--old COMMIT] [--peer PATH]
                              [--out DIR] [--only LIST] [--no-instructions]

  --quick            fewer rounds and collisions (a check of the script, not a measurement);
                     output to build/speed-targets-quick/ unless --out is given
  --rounds K         alternating rounds of every timed comparison (default 8 for the small
                     systems, 3 for N = 256000; --quick: 1)
  --build DIR        the Release build of the current tree (default build/; make build)
  --old COMMIT       the commit before issue 15, for e1 (default 20453f7); built in a detached
                     worktree ${TMPDIR:-/tmp}/hardbody-old-SHA, as bench/compare_builds.sh does
  --peer PATH        F. Smallenburg's EDMD source (github FSmallenburg/EDMD): runs
                     scripts/peer-bench.sh on it (N = 4000, 32000, 10^6) into DIR; without it the
                     sphere rows are read from DIR/peer_hard_spheres.jsonl of an earlier run and
                     marked with that run's date
  --out DIR          where speed_targets.{md,jsonl} go (default docs/benchmarks)
  --only LIST        comma-separated targets to re-measure (peer, e1, e3, elong, sq, flatn); the
                     others are kept from DIR/speed_targets.jsonl
  --no-instructions  skip the callgrind instruction counts of e1 and sq (noise-free, ~6 min)

Every figure is a cost per collision (CPU time of the benchmark's own process over the measured
stretch, after its warm-up) or a ratio of two, measured in alternating whole processes (a, b, a,
b, ...) under nice; the ratios are those of the medians over the rounds, and the per-round
values are printed beside them. Commands of every benchmark are in the report. The machine is
shared: a target within a few per cent of its threshold is not decided by one session.
"""
import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from performance import run_bench  # noqa: E402  (one process, its JSON lines and CPU time)
TARGETS = ["peer", "e1", "e3", "elong", "sq", "flatn"]

# The protocols (bench_rigid / bench_ratio keys); docs/benchmarks/README.md uses the same.
E1 = dict(shape="ellipsoid", N=256, phi=0.5, X0=2, method="nnl", collisions=20000, warmup=5000, check=0)
E3 = dict(pair="spheres", N=256, phi=0.5, X0=2, b=0.5, eps_d="1e-5", shell=0.15, collisions=20000,
          warmup=5000, rounds=10)
ELONG = dict(shape="ellipsoid", eps_d="1e-5", shell=0.15, split=1, phi=0.4, auto_n=1, warmup=5000,
             warmup_per_particle=200, collisions=10000, check=0)
SQ = dict(shape="superquadric", N=512, phi=0.256, inertia=1, eps_d="1e-5", shell=0.15, split=1, X0=0.5,
          b=1.6, warmup=10000, collisions=20000, check=0)
FLATN = dict(shape="ellipsoid", b=0.5, eps_d="1e-5", shell=0.15, split=1, phi=0.5, X0=2, warmup=5000,
             warmup_per_particle=3, collisions=300000, check=0)
QUICK = dict(e1=dict(collisions=3000, warmup=1000), e3=dict(collisions=3000, warmup=1000, rounds=2),
             elong=dict(warmup_per_particle=5, collisions=2000), sq=dict(collisions=2000, warmup=1000),
             flatn=dict(warmup_per_particle=0, collisions=20000))
FLATN_N = (256, 256000)
FLATN_N_QUICK = (256, 4096)


def keys(d):
    return [f"{k}={v}" for k, v in d.items()]


class Bench:
    def __init__(self):
        self.cpu = 0.0  # CPU seconds of the benchmark processes so far

    def run(self, exe, args, label):
        """Runs one benchmark process under nice; returns its last JSON line."""
        cmd = ["nice", "-n", "10", exe] + list(args)
        rows, cpu = run_bench(cmd, "speed_targets")
        self.cpu += cpu
        if not rows:
            sys.exit(f"speed_targets: no JSON line from {' '.join(cmd)}")
        r = rows[-1]
        if r.get("status", "ok") != "ok":
            sys.exit(f"speed_targets: {' '.join(cmd)} ended with status {r.get('status')}")
        v = r.get("tau_c_us", r.get("ratio_median"))
        print(f"  {label}: {v:.4g}  (CPU so far {self.cpu:.0f} s)", file=sys.stderr)
        return r

    def instructions(self, exe, args):
        """Instructions a collision under callgrind: the difference of two runs (3000 and 13000
        measured collisions), so start-up and warm-up cancel."""
        counts = []
        for c in (3000, 13000):
            a = [x for x in args if not x.startswith("collisions=")] + [f"collisions={c}"]
            p = subprocess.run(["nice", "-n", "10", "valgrind", "--tool=callgrind",
                                "--callgrind-out-file=/dev/null", exe] + a, capture_output=True, text=True)
            if p.returncode != 0:
                sys.exit(f"speed_targets: callgrind of {exe} failed: {p.stderr.strip()[-500:]}")
            line = [x for x in p.stderr.splitlines() if "Collected :" in x]
            counts.append(int(line[-1].split(":")[-1]))
        v = (counts[1] - counts[0]) / 10000
        print(f"  instructions a collision: {v:.4g}", file=sys.stderr)
        return v


def med(xs):
    return statistics.median(xs)


def alternate(bench, rounds, points):
    """points: [(name, exe, args)]; K rounds of all points in turn. Returns {name: [rows]}."""
    out = {name: [] for name, _, _ in points}
    for r in range(rounds):
        for name, exe, args in points:
            out[name].append(bench.run(exe, args, f"round {r + 1} {name}"))
    return out


def old_build(commit):
    sha = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", commit], capture_output=True, text=True,
                         check=True).stdout.strip()
    wt = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"hardbody-old-{sha}")
    exe = os.path.join(wt, "build", "bench", "bench_rigid")
    if not os.access(exe, os.X_OK):
        if not os.path.isdir(wt):
            subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", wt, commit], check=True)
        subprocess.run(["cmake", "-S", wt, "-B", os.path.join(wt, "build"), "-DCMAKE_BUILD_TYPE=Release",
                        "-DHB_BUILD_TESTS=OFF", "-DHB_BUILD_PYTHON=OFF", "-DPython3_EXECUTABLE=/usr/bin/python3"],
                       check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", os.path.join(wt, "build"), "-j", str(os.cpu_count() or 1),
                        "--target", "bench_rigid"], check=True, stdout=subprocess.DEVNULL)
    return sha, exe


def quick_args(base, name, quick):
    d = dict(base)
    if quick:
        d.update(QUICK[name])
    return d


def measure_e1(bench, a, rigid):
    sha, old = old_build(a.old)
    args = keys(quick_args(E1, "e1", a.quick))
    res = alternate(bench, a.rounds_small, [("old", old, args), ("new", rigid, args)])
    to, tn = [r["tau_c_us"] for r in res["old"]], [r["tau_c_us"] for r in res["new"]]
    row = dict(target="e1", what=f"ellipsoids X0 = 2, phi = 0.5, N = 256, NNL: new / old ({sha})",
               threshold="<= 0.25", value=med(tn) / med(to), old_us=med(to), new_us=med(tn),
               old_rounds=to, new_rounds=tn, round_ratios=[n / o for n, o in zip(tn, to)],
               commands=[f"{old} {' '.join(args)}", f"bench_rigid {' '.join(args)}"], old_commit=sha)
    if a.instructions:
        io, inew = bench.instructions(old, args), bench.instructions(rigid, args)
        row.update(old_instructions=io, new_instructions=inew, instruction_ratio=inew / io)
    row["met"] = row["value"] <= 0.25
    return [row]


def measure_e3(bench, a, ratio_exe):
    args = keys(quick_args(E3, "e3", a.quick))
    r = bench.run(ratio_exe, args, "bench_ratio")
    return [dict(target="e3", what="ellipsoid X0 = 2 / hard sphere cost, phi = 0.5, N = 256, one process",
                 threshold="<= 8", value=r["ratio_median"], ratio_min=r["ratio_min"], ratio_max=r["ratio_max"],
                 slices=E3["rounds"] if not a.quick else QUICK["e3"]["rounds"],
                 commands=[f"bench_ratio {' '.join(args)}"], met=r["ratio_median"] <= 8)]


def measure_elong(bench, a, rigid):
    base = quick_args(ELONG, "elong", a.quick)
    # the smallest semi-axis is 0.5 at every X0 (oblate: b = 0.5 / X0), as in docs/performance.md (e2)
    pts = {x0: dict(base, X0=x0, b=0.5 / min(x0, 1.0)) for x0 in (10.0, 1.0, 0.1)}
    first = bench.run(rigid, keys(dict(pts[10.0], N=256)), "N for X0 = 10")
    n = first["N"]
    points = [(f"X0={x0:g}", rigid, keys(dict(p, N=n))) for x0, p in pts.items()]
    res = alternate(bench, a.rounds_small if not a.quick else 1, points)
    t = {k: [r["tau_c_us"] for r in v] for k, v in res.items()}
    rows = []
    for x0 in ("10", "0.1"):
        v = med(t[f"X0={x0}"]) / med(t["X0=1"])
        rows.append(dict(target=f"elong_{x0}", group="elong",
                         what=f"ellipsoids, NNL, phi = 0.4, N = {n}: tau_c(X0 = {x0}) / tau_c(X0 = 1)",
                         threshold="<= 2", value=v, us=med(t[f"X0={x0}"]), us_x0_1=med(t["X0=1"]),
                         rounds=t[f"X0={x0}"], rounds_x0_1=t["X0=1"],
                         round_ratios=[u / w for u, w in zip(t[f"X0={x0}"], t["X0=1"])],
                         commands=[f"bench_rigid {' '.join(c)}" for nm, _, c in points if nm in (f"X0={x0}", "X0=1")],
                         met=v <= 2))
    return rows


def measure_sq(bench, a, rigid):
    base = quick_args(SQ, "sq", a.quick)
    points = [(f"p={p}", rigid, keys(dict(base, p=p))) for p in (2, 8)]
    res = alternate(bench, a.rounds_small, points)
    t2, t8 = [r["tau_c_us"] for r in res["p=2"]], [r["tau_c_us"] for r in res["p=8"]]
    v = med(t8) / med(t2)
    row = dict(target="sq", what="superquadrics (2, 2, p), N = 512, phi = 0.256, NNL: tau_c(p = 8) / tau_c(p = 2)",
               threshold="<= 1.5", value=v, us_p2=med(t2), us_p8=med(t8), rounds_p2=t2, rounds_p8=t8,
               round_ratios=[u / w for u, w in zip(t8, t2)],
               commands=[f"bench_rigid {' '.join(c)}" for _, _, c in points], met=v <= 1.5)
    if a.instructions:
        i2, i8 = (bench.instructions(rigid, c) for _, _, c in points)
        row.update(p2_instructions=i2, p8_instructions=i8, instruction_ratio=i8 / i2)
    return [row]


def measure_flatn(bench, a, rigid):
    base = quick_args(FLATN, "flatn", a.quick)
    lo, hi = FLATN_N_QUICK if a.quick else FLATN_N
    points = [(f"N={n}", rigid, keys(dict(base, N=n))) for n in (hi, lo)]
    res = alternate(bench, a.rounds_large, points)
    tl, th = [r["tau_c_us"] for r in res[f"N={lo}"]], [r["tau_c_us"] for r in res[f"N={hi}"]]
    v = med(th) / med(tl)
    return [dict(target="flatn_ellipsoids", group="flatn",
                 what=f"ellipsoids X0 = 2, phi = 0.5, NNL: tau_c(N = {hi}) / tau_c(N = {lo})",
                 threshold="<= 1.3", value=v, us_small=med(tl), us_large=med(th), rounds_small=tl, rounds_large=th,
                 round_ratios=[u / w for u, w in zip(th, tl)],
                 commands=[f"bench_rigid {' '.join(c)}" for _, _, c in points], met=v <= 1.3)]


def peer_rows(a, out):
    path = os.path.join(out, "peer_hard_spheres.jsonl")
    if a.peer:
        cmd = [os.path.join(ROOT, "scripts", "peer-bench.sh"), a.peer, "--out", out]
        if a.quick:
            cmd.append("--quick")
        subprocess.run(cmd, check=True)
    if not os.path.exists(path):
        return [dict(target="peer", what="hard spheres against EDMD Single", threshold=">= 1.5",
                     value=None, met=None, note="not measured: give --peer PATH")]
    peer = [json.loads(x) for x in open(path)]
    # rows of an earlier peer run keep its date (the report marks them)
    when = None if a.peer else (peer[0].get("date") or "an earlier session (date in peer_hard_spheres.md)")
    src = "scripts/peer-bench.sh"
    rows = []
    for r in peer:
        rows.append(dict(target=f"peer_{r['N']}", group="peer",
                         what=f"hard spheres, phi = 0.45, N = {r['N']}: ours / EDMD Single, collisions per CPU second",
                         threshold=">= 1.5", value=r["ratio_ours_over_peer"], ours_rounds=r["ours_rounds"],
                         round_ratios=[o / q for o, q in zip(r["ours_rounds"], r["peer_rounds"])],
                         peer_rounds=r["peer_rounds"], source=src, met=r["ratio_ours_over_peer"] >= 1.5))
        if when:
            rows[-1]["date"] = when
    big = max(peer, key=lambda r: r["N"])
    small = min(peer, key=lambda r: r["N"])
    eng = big.get("ours_engine_bytes_per_body")
    rows.append(dict(target="memory", group="peer", what=f"hard spheres, N = {big['N']}: the engine's bytes a body",
                     threshold="<= 216", value=eng, rss_bytes_per_body=big["ours_bytes_per_body"], source=src,
                     met=None if eng is None else eng <= 216))
    if when:
        rows[-1]["date"] = when
    v = big["ours_ns_per_collision"] / small["ours_ns_per_collision"]
    rows.append(dict(target="flatn_spheres", group="peer",
                     what=f"hard spheres, phi = 0.45: ns a collision at N = {big['N']} / at N = {small['N']}",
                     threshold="<= 2", value=v, source=src, met=v <= 2))
    if when:
        rows[-1]["date"] = when
    return rows


def fmt(v, digits=3, zeros=False):
    # zeros: keep trailing zeros (0.24997 prints 0.2500, not 0.25, beside a threshold of 0.25)
    return "—" if v is None else (f"{v:{'#' if zeros else ''}.{digits}g}" if abs(v) < 100 else f"{v:.0f}")



def report(rows, meta, path):
    lines = ["# Issue 15: the speed targets", "",
             f"Generated by `{meta['command']}` on {meta['date']}; do not edit by hand, rerun the script.", "",
             f"* Machine: {meta['cpu']}, shared; load before {meta['load_before']}, after {meta['load_after']}.",
             f"* Code: commit `{meta['commit']}`, Release build `{meta['build']}`.",
             "* Every figure: cost per collision in CPU time of the benchmark's own process after its warm-up, "
             "or a ratio of two such costs measured in alternating whole processes (a, b, a, b, ...); ratios "
             "are those of the medians over the rounds. Rows re-used from an earlier run say so.", "",
             "| target | measured | threshold | verdict | rounds |", "|---|---|---|---|---|"]
    for r in rows:
        verdict = "not measured" if r.get("met") is None else ("**met**" if r["met"] else "**not met**")
        if "round_ratios" in r:
            per = ", ".join(fmt(x) for x in r["round_ratios"])
        elif "slices" in r:
            per = f"{r['slices']} alternating slices in one process, {fmt(r['ratio_min'])}-{fmt(r['ratio_max'])}"
        else:
            per = ""
        extra = ""
        if r["target"] == "e1":
            extra = f" ({fmt(r['new_us'])} us vs {fmt(r['old_us'])} us"
            if "instruction_ratio" in r:
                extra += f"; instructions {r['new_instructions'] / 1e3:.1f}k / {r['old_instructions'] / 1e3:.1f}k = {r['instruction_ratio']:.3f}"
            extra += ")"
        if r.get("group") == "flatn" and "us_large" in r:
            extra = f" ({fmt(r['us_large'])} us vs {fmt(r['us_small'])} us)"
        if r.get("group") == "elong":
            extra = f" ({fmt(r['us'])} us vs {fmt(r['us_x0_1'])} us)"
        if r["target"] == "sq":
            extra = f" ({fmt(r['us_p8'])} us vs {fmt(r['us_p2'])} us"
            if "instruction_ratio" in r:
                extra += f"; instructions {r['p8_instructions'] / 1e3:.1f}k / {r['p2_instructions'] / 1e3:.1f}k = {r['instruction_ratio']:.3f}"
            extra += ")"
        if r.get("date") and r["date"] != meta["date"]:
            extra += f" [kept from the run of {r['date']}, commit {r.get('commit', '?')}]"
        # the value with one digit more than the rest: e1's 0.2505 must not print as its threshold
        lines.append(f"| {r['what']} | {fmt(r['value'], 4, zeros=True)}{extra} | {r['threshold']} | {verdict} | {per} |")
    lines += ["", "The last column: the ratio in each round (ours / peer for the hard spheres), so the spread can be "
              "read; the rows without it are derived from the hard-sphere runs above.", "", "## Commands", ""]
    for r in rows:
        for c in r.get("commands", []):
            lines.append(f"* {r['target']}: `{c}`")
        if r.get("source"):
            lines.append(f"* {r['target']}: {r['source']}, see peer_hard_spheres.md")
    open(path, "w").write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rounds", type=int)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--old", default="20453f7")
    ap.add_argument("--peer")
    ap.add_argument("--out")
    ap.add_argument("--only")
    ap.add_argument("--no-instructions", dest="instructions", action="store_false")
    a = ap.parse_args()
    out = a.out or os.path.join(ROOT, "build/speed-targets-quick" if a.quick else "docs/benchmarks")
    os.makedirs(out, exist_ok=True)
    only = TARGETS if not a.only else a.only.split(",")
    bad = [t for t in only if t not in TARGETS]
    if bad:
        print(f"speed_targets: unknown target(s) {', '.join(bad)}; known: {', '.join(TARGETS)}", file=sys.stderr)
        sys.exit(2)
    a.rounds_small = a.rounds or (1 if a.quick else 8)
    a.rounds_large = a.rounds or (1 if a.quick else 3)
    if a.quick:
        a.instructions = False
    rigid = os.path.join(a.build, "bench", "bench_rigid")
    ratio = os.path.join(a.build, "bench", "bench_ratio")
    cache = os.path.join(a.build, "CMakeCache.txt")
    if not (os.access(rigid, os.X_OK) and os.access(ratio, os.X_OK)) or \
            "CMAKE_BUILD_TYPE:STRING=Release" not in open(cache).read():
        sys.exit(f"speed_targets: no Release build with bench_rigid and bench_ratio in {a.build} (make build)")
    jpath = os.path.join(out, "speed_targets.jsonl")
    kept = []
    if a.only:
        if not os.path.exists(jpath):
            sys.exit(f"speed_targets: --only needs an earlier {jpath}")
        kept = [json.loads(x) for x in open(jpath) if not x.startswith('{"meta"')]
        kept = [r for r in kept if r.get("group", r["target"]) not in only]
    bench = Bench()
    load_before = os.getloadavg()[0]
    t0 = time.time()
    new = []
    for t in only:
        print(f"[{t}]", file=sys.stderr)
        if t == "peer":
            new += peer_rows(a, out)
        elif t == "e1":
            new += measure_e1(bench, a, rigid)
        elif t == "e3":
            new += measure_e3(bench, a, ratio)
        elif t == "elong":
            new += measure_elong(bench, a, rigid)
        elif t == "sq":
            new += measure_sq(bench, a, rigid)
        elif t == "flatn":
            new += measure_flatn(bench, a, rigid)
    order = {t: i for i, t in enumerate(TARGETS)}
    rows = sorted(kept + new, key=lambda r: order.get(r.get("group", r["target"]), 99))
    # the code measured: HEAD, "-dirty" when src/, bench/, apps/ or the build files have uncommitted
    # changes (the reports this script rewrites do not count)
    git = lambda *x: subprocess.run(["git", "-C", ROOT] + list(x), capture_output=True, text=True).stdout.strip()
    commit = git("rev-parse", "--short", "HEAD") + \
        ("-dirty" if git("status", "--porcelain", "--", "src", "bench", "apps", "CMakeLists.txt", "cmake") else "")
    cpu = subprocess.run(["sh", "-c", "lscpu | sed -n 's/^Model name: *//p' | head -1"], capture_output=True,
                         text=True).stdout.strip()
    meta = dict(meta=True, date=datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M:%S UTC"), commit=commit, cpu=cpu,
                build=os.path.relpath(a.build, ROOT), load_before=f"{load_before:.2f}",
                load_after=f"{os.getloadavg()[0]:.2f}", wall_s=round(time.time() - t0),
                command="bench/speed_targets.py " + " ".join(sys.argv[1:]))
    for r in new:
        r.setdefault("date", meta["date"])
        r.setdefault("commit", commit)
    with open(jpath + ".tmp", "w") as f:
        f.write(json.dumps(meta) + "\n")
        for r in rows:
            f.write(json.dumps(r) + "\n")
    os.replace(jpath + ".tmp", jpath)
    report(rows, meta, os.path.join(out, "speed_targets.md"))
    print(open(os.path.join(out, "speed_targets.md")).read())


if __name__ == "__main__":
    main()
