#!/usr/bin/python3
"""Runs the paper's performance study (sections 4 and 5) on this code.

Called by scripts/performance.sh. Every measurement is one run of bench_rigid or bench_ratio
(one process at a time, under nice); their JSON lines go to OUT/raw.jsonl with the study they
belong to, the source they were measured with ("source": the commit, with "-dirty" for a working
tree with uncommitted changes in src/ or bench/) and the date of the run ("date"), and
OUT/meta.json records the machine, its load, the source and the CPU time spent.
scripts/performance_plot.py then writes the CSV tables, the plots and OUT.md.

Studies (section numbers of docs/performance.md):
  a  tau_c vs phi, cells and NNL, X0 = 0.5 and 2, N = 256           (paper Fig. CollTimePhi)
  b  tau_c(cells) / tau_c(NNL) vs X0 at phi = 0.3, 0.4, 0.5          (paper Fig. CollTimeX0)
  c  tau_c vs eps_d                                                   (paper Fig. epsd)
  d  tau_c vs the NNL shell at the paper's state points               (paper Fig. delta)
  e  the issue-4 targets (studies e1, e2, e3, e4)
  f  superquadrics: tau_c vs p, N = 512, phi = 0.256                  (paper Fig. SQsims; studies f,
     f_long, f_ratio)
  profile  perf call-graph profiles of three points (OUT/profile.json)

Partial re-run (--only STUDIES, comma-separated study-name prefixes, e.g. "f" for f, f_long and
f_ratio, or "f,e3"): runs only the plan entries whose study starts with one of the prefixes, and
the perf profile only if the list holds the word "profile". It then merges: the rows of
OUT/raw.jsonl whose study matches a prefix are dropped, the new rows appended, and raw.jsonl
rewritten atomically; meta.json keeps the original run's fields and gains an entry in its list
"updates" (studies, date, source, CPU and wall time, uptime before and after). OUT/raw.jsonl and
OUT/meta.json of an earlier run of the same mode (full or quick) must exist (exit status 2
otherwise). --dry-run prints the benchmark commands that would run, and runs nothing.
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Full and quick plans. Collision counts are per measurement; warm-ups start from the aligned
# lattice and are long enough to melt it (S2 is recorded to show how far it got).
FULL = dict(
    a_x0=[0.5, 2.0], a_phi=[0.30, 0.35, 0.40, 0.45, 0.50, 0.55], a_warm=20000, a_coll=20000,
    b_x0=[0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 7.0, 10.0], b_phi=[0.3, 0.4, 0.5],
    b_warm_pp=20, b_coll=10000, b_budget=6,
    c_points=[(0.5, 0.30), (0.5, 0.55), (2.0, 0.30), (2.0, 0.55)],
    c_eps=["1e-6", "1e-5", "1e-4", "1e-3", "1e-2", "1e-1"], c_warm=20000, c_coll=10000,
    d_points=[(0.5, 0.45), (0.5, 0.57), (2.0, 0.45), (2.0, 0.57)],
    d_shell=[0.02, 0.03, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5], d_warm=20000, d_coll=10000,
    e1_seeds=[1, 2, 3], e1_warm=20000, e1_coll=50000,
    # e2: 200 warm-up collisions per body. At 40 the X0 = 10 start had not relaxed: its rebuilds
    # per collision were 0.105 in the measured stretch against 0.24 after 200 or 600 per body
    # (S2 0.994 -> 0.957, 0.949; docs/benchmarks/README.md, "Session of 2026-12-01, third part").
    e2_x0=[0.1, 1.0, 2.0, 5.0, 10.0], e2_warm_pp=200, e2_coll=10000, e2_rounds=3,
    e3_coll=20000, e3_warm=20000,
    e4_n=[256, 1024, 4096, 32000, 256000], e4_warm_pp=40, e4_coll=20000,
    f_x0=[2.0, 0.5], f_p=[2, 3, 4, 5, 6, 8, 10, 12, 14, 16], f_warm=10000, f_coll=5000, f_budget=10,
    f_long_p=[16], f_long_coll=50000,
    f_ratio_coll=10000, f_ratio_warm=10000,
)
QUICK = dict(
    a_x0=[0.5, 2.0], a_phi=[0.30, 0.45, 0.55], a_warm=4000, a_coll=3000,
    b_x0=[0.2, 1.0, 2.0, 5.0, 10.0], b_phi=[0.4], b_warm_pp=5, b_coll=2000, b_budget=1.5,
    c_points=[(2.0, 0.50)], c_eps=["1e-6", "1e-4", "1e-2", "1e-1"], c_warm=4000, c_coll=3000,
    d_points=[(2.0, 0.45), (2.0, 0.57)], d_shell=[0.02, 0.05, 0.1, 0.2, 0.5], d_warm=4000, d_coll=3000,
    e1_seeds=[1], e1_warm=4000, e1_coll=5000,
    e2_x0=[0.1, 1.0, 2.0, 5.0, 10.0], e2_warm_pp=5, e2_coll=2000, e2_rounds=1,
    e3_coll=5000, e3_warm=4000,
    e4_n=[256, 4096, 32000], e4_warm_pp=5, e4_coll=3000,
    f_x0=[2.0], f_p=[2, 4, 8, 16], f_warm=2000, f_coll=1000, f_budget=3,
    f_long_p=[], f_long_coll=0,
    f_ratio_coll=2000, f_ratio_warm=2000,
)

# The paper's ellipsoid settings (section 4.2): eps_d = 1e-5, Delta_NNL = 0.15, N = 256.
ELL = dict(shape="ellipsoid", b=0.5, eps_d="1e-5", shell=0.15, split=1)
# The paper's superquadrics (section 5.1): N = 512, phi = 0.256, smallest semi-axis 0.8,
# exponents (2, 2, p), I = 1.
SQ = dict(shape="superquadric", N=512, phi=0.256, inertia=1, eps_d="1e-5", shell=0.15, split=1)


def equatorial_b(x0, smallest):
    """Equatorial semi-axis b of a body of elongation X0 = a / b whose smallest semi-axis is `smallest`."""
    return smallest / min(x0, 1.0)


def matches(study, prefixes):
    """Whether a study name starts with one of the prefixes of --only."""
    return any(study.startswith(p) for p in prefixes)


def merge_rows(old_rows, new_rows, prefixes):
    """The rows of a partial re-run merged into an earlier run's: every old row whose study starts
    with one of the prefixes is dropped and the new rows (all of re-run studies) are appended in
    their order. The other rows keep their order."""
    stray = sorted({r.get("study", "?") for r in new_rows if not matches(r.get("study", ""), prefixes)})
    if stray:
        raise ValueError(f"new rows of studies outside --only: {', '.join(stray)}")
    return [r for r in old_rows if not matches(r.get("study", ""), prefixes)] + list(new_rows)


def run_bench(cmd, who):
    """Runs one benchmark process; returns its JSON lines and the CPU seconds it took (user + sys).
    Exits with a message naming `who` when the process fails."""
    t0 = os.times()
    p = subprocess.run(cmd, capture_output=True, text=True)
    t1 = os.times()
    cpu = (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
    if p.returncode != 0:
        sys.exit(f"{who}: {' '.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
    return [json.loads(line) for line in p.stdout.splitlines() if line.startswith("{")], cpu


class Runner:
    """Runs one benchmark per call and records its rows. only: study prefixes to run (None: all);
    stamp: fields added to every row (source, date); dry_run: print the commands, run nothing.
    The rows also go, as they come, to OUT/raw.jsonl.tmp (OUT/raw.jsonl.new.tmp for --only)."""

    def __init__(self, build, out, stamp=None, only=None, dry_run=False):
        self.build = build
        self.stamp = stamp or {}
        self.only = only
        self.dry_run = dry_run
        self.rows = []
        self.raw_path = os.path.join(out, "raw.jsonl.tmp" if only is None else "raw.jsonl.new.tmp")
        self.raw = None if dry_run else open(self.raw_path, "w")
        self.cpu = 0.0

    def __call__(self, bench, study, **kw):
        if self.only is not None and not matches(study, self.only):
            return []
        exe = os.path.join(self.build, "bench", bench)
        cmd = ["nice", "-n", "10", exe] + [f"{k}={v}" for k, v in kw.items()]
        if self.dry_run:
            print(f"[{study}] {' '.join([bench] + cmd[4:])}")
            return []
        rows, cpu = run_bench(cmd, "performance")
        self.cpu += cpu
        for r in rows:
            r["study"] = study
            r["command"] = " ".join([bench] + cmd[4:])
            r["load1"] = os.getloadavg()[0]  # machine load when the run ended
            r.update(self.stamp)
            self.rows.append(r)
            self.raw.write(json.dumps(r) + "\n")
            self.raw.flush()
            tau = r.get("tau_c_us", r.get("ratio"))
            what = " ".join(f"{k}={r[k]}" for k in ("shape", "N", "phi", "X0", "p", "method", "shell", "eps_d")
                            if k in r)
            print(f"[{study}] {what} -> {r.get('status', 'ok')} "
                  f"{'' if tau is None else f'{tau:.4g}'} (CPU so far {self.cpu:.0f} s)", file=sys.stderr)
        return rows


def plan(run, c):
    methods = "method:nnl,cells"  # measured on one trajectory: NNL first, then cells
    # (a) tau_c vs phi
    for x0 in c["a_x0"]:
        for phi in c["a_phi"]:
            run("bench_rigid", "a", **ELL, N=256, phi=phi, X0=x0, auto_n=1, warmup=c["a_warm"],
                collisions=c["a_coll"], scan=methods)
    # (b) cells / NNL vs X0 (N raised where the box would be smaller than 4 circumradii)
    for phi in c["b_phi"]:
        for x0 in c["b_x0"]:
            run("bench_rigid", "b", **ELL, N=256, phi=phi, X0=x0, auto_n=1, warmup=5000,
                warmup_per_particle=c["b_warm_pp"], collisions=c["b_coll"], budget=c["b_budget"],
                scan=methods)
    # (c) eps_d
    for x0, phi in c["c_points"]:
        run("bench_rigid", "c", **ELL, N=256, phi=phi, X0=x0, auto_n=1,
            warmup=c["c_warm"], collisions=c["c_coll"], scan="eps_d:" + ",".join(c["c_eps"]))
    # (d) the NNL shell
    for x0, phi in c["d_points"]:
        run("bench_rigid", "d", **ELL, N=256, phi=phi, X0=x0, auto_n=1, warmup=c["d_warm"],
            collisions=c["d_coll"], scan="shell:" + ",".join(str(s) for s in c["d_shell"]))
    # (e1) tau_c at X0 = 2, phi = 0.5, N = 256, NNL
    for seed in c["e1_seeds"]:
        run("bench_rigid", "e1", **ELL, N=256, phi=0.5, X0=2, seed=seed, warmup=c["e1_warm"],
            collisions=c["e1_coll"])
    # (e2) NNL over X0 at phi = 0.4, all at the N the longest body needs; the ratios to X0 = 1
    # are the target, so the X0 are measured in alternating rounds (the report takes medians).
    # Lengths in units of the smallest semi-axis, the paper's convention (its section 5): the
    # smallest semi-axis is b = 0.5 at every X0 (oblate bodies: b = 0.5 / X0), so the shell and
    # eps_d are the same fraction of it at every elongation.
    n_common = None
    for _ in range(c["e2_rounds"]):
        for x0 in sorted(c["e2_x0"], reverse=True):
            rows = run("bench_rigid", "e2", **dict(ELL, b=equatorial_b(x0, 0.5)), N=n_common or 256, phi=0.4,
                       X0=x0, auto_n=1,
                       warmup=5000, warmup_per_particle=c["e2_warm_pp"], collisions=c["e2_coll"])
            n_common = n_common or (rows[0]["N"] if rows else None)
    # (e3) ellipsoids (X0 = 2) against hard spheres, one process
    run("bench_ratio", "e3", pair="spheres", N=256, phi=0.5, X0=2, b=0.5, eps_d="1e-5", shell=0.15,
        collisions=c["e3_coll"], warmup=c["e3_warm"], rounds=10)
    # (e4) cost per collision vs N
    for n in c["e4_n"]:
        run("bench_rigid", "e4", **ELL, N=n, phi=0.5, X0=2, warmup=5000,
            warmup_per_particle=c["e4_warm_pp"], collisions=c["e4_coll"])
    # (f) superquadrics
    for x0 in c["f_x0"]:
        for p in c["f_p"]:
            run("bench_rigid", "f", **SQ, X0=x0, b=equatorial_b(x0, 0.8), p=p, warmup=c["f_warm"],
                collisions=c["f_coll"], budget=c["f_budget"], scan=methods)
    for x0 in c["f_x0"]:
        for p in c["f_long_p"]:
            # another seed than (f): an independent trajectory
            run("bench_rigid", "f_long", **SQ, X0=x0, b=equatorial_b(x0, 0.8), p=p, seed=2, warmup=c["f_warm"],
                collisions=c["f_long_coll"], method="nnl")
    run("bench_ratio", "f_ratio", pair="superquadric", N=512, phi=0.256, X0=2, b=equatorial_b(2.0, 0.8),
        inertia=1, eps_d="1e-5", shell=0.15, collisions=c["f_ratio_coll"], warmup=c["f_ratio_warm"],
        rounds=10)


# Functions whose inclusive share of the CPU samples the profile reports (regex on the symbol).
PROFILE_FUNCTIONS = [
    ("contact-time predictions", r"hb::contact_time<"),
    ("  distance solves (NR)", r"hb::distance<"),
    ("  separating-axis advancement", r"advance_on_axis|hb::separating_axis<"),
    ("NNL rebuilds: escape time", r"hb::escape_time<"),
    ("NNL rebuilds: box overlaps", r"hb::obb_overlap"),
    ("collision impulse", r"RigidBodies<.*>::collide"),
    ("free rotation (pose at time t)", r"hb::orientation_at"),
    ("superquadric support point", r"Superquadric::support_point"),
    ("superquadric bounding radius", r"Superquadric::bounding_radius"),
    ("superquadric 1-D log root", r"sq_detail::log_root"),
]


def profile(run, c, out):
    """perf call-graph profiles of a few points: inclusive share of the samples per function.
    Writes OUT/profile.json (atomically) and returns True, or returns False (no perf, perf failed)."""
    import re
    import shutil
    import tempfile
    if run.dry_run:
        print("[profile] 3 perf record runs of bench_rigid -> profile.json")
        return False
    if not shutil.which("perf"):
        print("performance: perf not found, no profile", file=sys.stderr)
        return False
    points = [
        ("ellipsoid X0 = 2, phi = 0.5, N = 256, NNL",
         dict(ELL, N=256, phi=0.5, X0=2, warmup=c["e1_warm"], collisions=2 * c["e1_coll"], split=0)),
        ("ellipsoid X0 = 10, phi = 0.4, NNL",
         dict(ELL, N=256, phi=0.4, X0=10, auto_n=1, warmup=5000, collisions=c["e2_coll"], split=0)),
        ("superquadric X0 = 2, p = 8, NNL",
         dict(SQ, X0=2, b=equatorial_b(2.0, 0.8), p=8, warmup=c["f_warm"], collisions=c["f_coll"], split=0)),
    ]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, kw in points:
            data = os.path.join(tmp, "perf.data")
            exe = os.path.join(run.build, "bench", "bench_rigid")
            cmd = ["nice", "-n", "10", "perf", "record", "-q", "--call-graph", "dwarf,16384", "-F", "200",
                   "-o", data, exe, "check=0"] + [f"{k}={v}" for k, v in kw.items()]
            t0 = os.times()
            p = subprocess.run(cmd, capture_output=True, text=True)
            t1 = os.times()
            run.cpu += (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
            if p.returncode != 0:
                print(f"performance: perf failed ({p.stderr.strip()[:200]}), no profile", file=sys.stderr)
                return False
            rep = subprocess.run(["perf", "report", "-i", data, "--children", "--sort", "symbol", "--stdio",
                                  "-q", "-g", "none"], capture_output=True, text=True).stdout
            syms = []
            for line in rep.splitlines():
                m = re.match(r"^\s*([\d.]+)%\s+([\d.]+)%\s+\[(.)\]\s+(.+?)\s*$", line)
                if m:
                    # the symbol, without the padding and empty columns perf appends
                    syms.append((float(m.group(1)), float(m.group(2)), re.split(r"\s{2,}", m.group(4))[0]))
            for name, rx in PROFILE_FUNCTIONS:
                share = max([s[0] for s in syms if re.search(rx, s[2])], default=0.0)
                rows.append(dict(point=label, kind="inclusive", function=name, percent=share))
            for incl, own, sym in sorted(syms, key=lambda s: -s[1])[:12]:
                rows.append(dict(point=label, kind="self", function=sym[:120], percent=own))
            print(f"[profile] {label}", file=sys.stderr)
    write_atomic(os.path.join(out, "profile.json"), lambda f: json.dump(rows, f, indent=0))
    return True


def write_atomic(path, write):
    """write(f) into path.tmp, then rename it over path."""
    with open(path + ".tmp", "w") as f:
        write(f)
    os.replace(path + ".tmp", path)


def sh(cmd):
    return subprocess.run(["sh", "-c", cmd], capture_output=True, text=True).stdout.strip()


def source_of(build):
    """Where the measured binaries come from: the source tree of the build and its commit."""
    src = sh(f"sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' '{build}/CMakeCache.txt'")
    info = {"build": os.path.abspath(build), "source": src}
    # the optimisation flags the benchmarks were compiled with (-O, -march, GCC's --param pairs)
    words = sh(f"sed -n 's/^CXX_FLAGS = //p' '{build}/bench/CMakeFiles/bench_rigid.dir/flags.make'").split()
    keep = [w for k, w in enumerate(words)
            if w.startswith(("-O", "-march")) or w == "--param" or (k > 0 and words[k - 1] == "--param")]
    if keep:
        info["cxx_flags"] = " ".join(keep)
    if os.path.exists(os.path.join(src, "SOURCE_COMMIT")):  # e.g. a `git archive` export
        info["commit"] = open(os.path.join(src, "SOURCE_COMMIT")).read().strip()
        info["source_note"] = "clean `git archive` export of the commit"
    elif os.path.isdir(os.path.join(src, ".git")):
        info["commit"] = sh(f"git -C '{src}' rev-parse HEAD")
        dirty = sh(f"git -C '{src}' status --porcelain -- src bench")
        info["source_note"] = "working tree" + (" with uncommitted changes in src/ or bench/" if dirty else "")
        info["dirty"] = bool(dirty)
    return info


def source_label(info):
    """The "source" field of the rows: the commit, "-dirty" appended for uncommitted changes."""
    return (info.get("commit") or "unknown") + ("-dirty" if info.get("dirty") else "")


def plan_studies(c):
    """The study names of the plan, in plan order (the plan run with a recorder, nothing measured)."""
    names = []

    def record(bench, study, **kw):
        if study not in names:
            names.append(study)
        return []
    plan(record, c)
    return names


def parse_only(text, studies):
    """--only STUDIES: (the study prefixes, whether to profile). ValueError for a prefix that
    matches no study of the plan, or an empty list."""
    items = [x.strip() for x in text.split(",") if x.strip()]
    prefixes = [x for x in items if x != "profile"]
    unknown = [x for x in prefixes if not any(s.startswith(x) for s in studies)]
    if unknown:
        raise ValueError(f"no study starts with {', '.join(unknown)} (studies: {', '.join(studies)}, profile)")
    if not items:
        raise ValueError("empty study list")
    return prefixes, "profile" in items


def read_rows(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def fail(msg, status=2):
    print(f"performance: {msg}", file=sys.stderr)
    sys.exit(status)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", required=True)
    ap.add_argument("--only", metavar="STUDIES",
                    help="comma-separated study prefixes (and/or 'profile') to re-run and merge into OUT")
    ap.add_argument("--dry-run", action="store_true", help="print the benchmark commands, run nothing")
    a = ap.parse_args()
    c = QUICK if a.quick else FULL
    mode = "quick" if a.quick else "full"
    studies = plan_studies(c)
    prefixes, with_profile = None, True
    if a.only is not None:
        try:
            prefixes, with_profile = parse_only(a.only, studies)
        except ValueError as e:
            fail(f"--only {a.only}: {e}")
        raw_path, meta_path = os.path.join(a.out, "raw.jsonl"), os.path.join(a.out, "meta.json")
        for path in (raw_path, meta_path):
            if not os.path.exists(path):
                fail(f"--only merges into an earlier run, but {path} does not exist: run the whole study first")
        old_rows = read_rows(raw_path)
        with open(meta_path) as f:
            old_meta = json.load(f)
        if old_meta.get("mode") != mode:
            fail(f"--only: {a.out} holds a {old_meta.get('mode')} run, this is a {mode} run; not merging "
                 f"({'drop --quick' if a.quick else 'add --quick'} or choose another --out)")
    rerun = [s for s in studies if prefixes is None or matches(s, prefixes)]
    if a.dry_run:
        print(f"performance: would run {', '.join(rerun) or 'no study'}" +
              (" and the profile" if with_profile else "") + f" ({mode} mode)", file=sys.stderr)
        run = Runner(a.build, a.out, only=prefixes, dry_run=True)
        plan(run, c)
        if with_profile:
            profile(run, c, a.out)
        return
    os.makedirs(a.out, exist_ok=True)
    src = source_of(a.build)
    date = time.strftime("%Y-%m-%d %H:%M:%S %Z")
    info = {
        "date": date,
        "uptime_before": sh("uptime"),
        **src,
        "source_label": source_label(src),
    }
    run = Runner(a.build, a.out, stamp=dict(source=info["source_label"], date=date), only=prefixes)
    t0 = time.time()
    plan(run, c)
    profiled = profile(run, c, a.out) if with_profile else False
    run.raw.close()
    info.update(uptime_after=sh("uptime"), cpu_seconds=round(run.cpu, 1), wall_seconds=round(time.time() - t0, 1))
    if prefixes is None:
        os.replace(run.raw_path, os.path.join(a.out, "raw.jsonl"))
        meta = {"mode": mode, "date": date, "cpu_model": sh("lscpu | sed -n 's/^Model name: *//p'"),
                "cores": os.cpu_count(), **info}
    else:
        merged = merge_rows(old_rows, run.rows, prefixes)
        write_atomic(os.path.join(a.out, "raw.jsonl"), lambda f: f.writelines(json.dumps(r) + "\n" for r in merged))
        os.remove(run.raw_path)  # the new rows alone, kept until the merge was written
        meta = old_meta
        meta.setdefault("updates", []).append({
            "studies": rerun + (["profile"] if profiled else []), "only": a.only, "mode": mode,
            "cpu_model": sh("lscpu | sed -n 's/^Model name: *//p'"), "cores": os.cpu_count(), **info})
        print(f"performance: merged {len(run.rows)} new rows of {', '.join(rerun) or 'no study'} into "
              f"{a.out}/raw.jsonl (dropped {len(old_rows) + len(run.rows) - len(merged)} old rows)" +
              ("" if profiled or not with_profile else "; the profile was not redone"), file=sys.stderr)
    write_atomic(os.path.join(a.out, "meta.json"), lambda f: json.dump(meta, f, indent=1))
    print(f"performance: {run.cpu:.0f} s CPU, {time.time() - t0:.0f} s wall", file=sys.stderr)


if __name__ == "__main__":
    main()
