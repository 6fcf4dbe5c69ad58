#!/usr/bin/env python3
"""Campaigns of many hardbody runs: ``hardbody campaign`` (docs/campaigns.md).

    hardbody campaign CAMPAIGN.toml [--jobs N] [--executor local|slurm] [--retry-failed] [--wait]
    hardbody campaign status CAMPAIGN.toml
    hardbody campaign results CAMPAIGN.toml      (results.csv and plots from what is finished)

A campaign file names a base config, a grid of ``--set`` values, seeds, the summary keys to
collect and an output directory (DESIGN.md, "Campaigns"). The runs go through an existing
engine: Snakemake on N local cores, or one Slurm ``sbatch --array`` job (campaign_exec.py).
Finished runs are never repeated, interrupted ones resume from their checkpoints, failed ones
(exit 2 or 3) are listed with their message and a reproducer and do not stop the others.

From Python (a notebook), with this folder on sys.path::

    import hardbody_campaign as hc
    c = hc.load("examples/campaigns/eos-ellipsoids.toml")
    hc.run(c, jobs=2)          # same as the command; returns the status of every run
    hc.status(c)               # {"done": [...], "running": [...], "failed": [...], "pending": [...]}
    rows = hc.results(c)       # list of dicts, the rows of results.csv (also written)

Exit statuses: 0 every run done; 2 bad campaign input (one message, nothing written) or a busy
campaign; 3 some run failed (listed); 4 runs remain (submitted to Slurm, or left pending);
128 + signal when stopped by SIGINT/SIGTERM (every running run wrote its checkpoint).
"""

from __future__ import annotations

import csv
import json
import math
import os
import shlex
import signal
import sys
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import campaign_exec as ex  # noqa: E402
from campaign_spec import Campaign, CampaignError, Run, load  # noqa: E402,F401

EXIT_BAD_INPUT, EXIT_FAILED, EXIT_PENDING = 2, 3, 4


class Stopped(Exception):
    """SIGINT/SIGTERM reached the campaign outside the engine's run."""

    def __init__(self, sig):
        super().__init__(f"signal {sig}")
        self.signal = sig
STATES = ["done", "running", "failed", "pending"]


def say(msg: str) -> None:
    print(f"hardbody campaign: {msg}", file=sys.stderr, flush=True)


def hardbody_binary() -> str:
    hb = os.environ.get("HARDBODY")
    if hb:
        return str(Path(hb).absolute())
    here = Path(__file__).resolve().parent.parent
    for cand in [here / "build" / "apps" / "hardbody" / "hardbody"]:
        if cand.is_file():
            return str(cand)
    return "hardbody"


# ----------------------------------------------------------------------------------------------
# State of each run
# ----------------------------------------------------------------------------------------------

def _locked_inodes() -> set[int]:
    """Inodes with a flock held (Linux /proc/locks): a running hardbody holds its run's lock."""
    try:
        text = Path("/proc/locks").read_text()
    except OSError:
        return set()
    res = set()
    for line in text.splitlines():
        f = line.split()
        if len(f) >= 6 and f[1] == "FLOCK":
            try:
                res.add(int(f[5].split(":")[2]))
            except (IndexError, ValueError):
                pass
    return res


def run_state(c: Campaign, run: Run, locked: set[int], queued: dict) -> dict:
    """State of one run: done (summary.json), running (its directory is locked by hardbody),
    failed (last attempt exited 2 or 3), pending (not started, interrupted, or queued)."""
    d = c.run_dir(run)
    try:
        st = json.loads((c.out / "status" / f"{run.name}.json").read_text())
    except (OSError, ValueError):
        st = {}
    info = {"run": run, "status": st}
    try:
        lock_ino = (d / ".hardbody.lock").stat().st_ino
    except OSError:
        lock_ino = None
    if lock_ino is not None and lock_ino in locked:
        info["state"] = "running"
    elif (d / "summary.json").is_file():
        info["state"] = "done"
    elif st.get("state") == "failed":
        info["state"] = "failed"
    else:
        info["state"] = "pending"
        if (d / "config.resolved.toml").exists():
            info["detail"] = "interrupted, resumes from its checkpoint"
    if run.name in queued and info["state"] == "pending":
        info["detail"] = f"Slurm: {queued[run.name]}"
    return info


def states(c: Campaign) -> list[dict]:
    locked = _locked_inodes()
    queued = ex.slurm_queued(c.out) if c.executor["type"] == "slurm" else {}
    return [run_state(c, r, locked, queued) for r in c.runs]


def status(c: Campaign) -> dict:
    """Run names by state: {"done": [...], "running": [...], "failed": [...], "pending": [...]}."""
    res = {s: [] for s in STATES}
    for i in states(c):
        res[i["state"]].append(i["run"].name)
    return res


def print_status(c: Campaign, infos: list[dict], out=sys.stdout) -> None:
    counts = {s: sum(1 for i in infos if i["state"] == s) for s in STATES}
    print(f"{c.path.name}: {len(infos)} runs in {c.out}: " +
          ", ".join(f"{counts[s]} {s}" for s in STATES), file=out)
    for i in infos:
        if i["state"] in ("running", "pending") and (i["state"] == "running" or "detail" in i):
            print(f"  {i['state']:8s} {i['run'].name}" + (f"  ({i['detail']})" if "detail" in i else ""), file=out)
    for i in infos:
        if i["state"] == "failed":
            st = i["status"]
            print(f"  failed   {i['run'].name} (exit {st.get('exit')}): {st.get('message', '')}", file=out)
            print(f"           reproducer: {st.get('reproducer', '')}", file=out)
            print(f"           log: {c.out / 'logs' / (i['run'].name + '.log')}", file=out)


# ----------------------------------------------------------------------------------------------
# results.csv and plots
# ----------------------------------------------------------------------------------------------

def _base_seed(c: Campaign):
    with open(c.base, "rb") as f:
        return tomllib.load(f).get("system", {}).get("seed", 1)


def _number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and v is not None


def results(c: Campaign, write: bool = True, plots: bool = True) -> list[dict]:
    """One row per run (grid values, seed, status, collected keys and their errors); writes
    OUT/results.csv, OUT/results_pooled.csv and OUT/<key>.png unless told not to."""
    infos = states(c)
    summaries = {}
    for i in infos:
        if i["state"] == "done":
            summaries[i["run"].name] = json.loads((c.run_dir(i["run"]) / "summary.json").read_text())
    has_error = {k: any(f"{k}_error" in s for s in summaries.values()) for k in c.collect}
    cols = list(c.keys) + ["seed", "status"]
    for k in c.collect:
        cols.append(k)
        if has_error[k]:
            cols.append(f"{k}_error")
    cols.append("run")
    seed0 = _base_seed(c)
    rows = []
    for i in infos:
        r = i["run"]
        row = {k: r.params[k] for k in c.keys}
        row["seed"] = r.seed if r.seed is not None else seed0
        row["status"] = i["state"] if i["state"] in ("done", "failed") else "pending"
        s = summaries.get(r.name, {})
        for k in c.collect:
            row[k] = s.get(k)
            if has_error[k]:
                row[f"{k}_error"] = s.get(f"{k}_error")
        row["run"] = r.name
        rows.append(row)
    if write:
        c.out.mkdir(parents=True, exist_ok=True)
        _write_csv(c.out / "results.csv", cols, rows)
        pooled = pool(c, rows)
        pcols = list(c.keys) + ["seeds"]
        for k in c.collect:
            pcols += [k, f"{k}_sem", f"{k}_block_error"]
        _write_csv(c.out / "results_pooled.csv", pcols, pooled)
        if plots:
            plot(c, rows, pooled)
    return rows


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (list, dict)):
        return json.dumps(v)
    return str(v)


def _write_csv(path: Path, cols: list, rows: list) -> None:
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            w.writerow([_cell(r.get(k)) for k in cols])
    os.replace(tmp, path)


def pool(c: Campaign, rows: list[dict]) -> list[dict]:
    """Seeds pooled per grid point: mean over the finished seeds, its standard error from the
    spread over seeds (needs 2 seeds), and the error of that mean from the runs' own block
    errors, sqrt(sum err^2) / n."""
    groups = {}
    for r in rows:
        key = json.dumps([r[k] for k in c.keys])
        groups.setdefault(key, []).append(r)
    out = []
    for key, rs in groups.items():
        done = [r for r in rs if r["status"] == "done"]
        p = {k: rs[0][k] for k in c.keys}
        p["seeds"] = len(done)
        for k in c.collect:
            vals = [r[k] for r in done if _number(r[k])]
            n = len(vals)
            p[k] = sum(vals) / n if n else None
            p[f"{k}_sem"] = (math.sqrt(sum((v - p[k]) ** 2 for v in vals) / (n - 1) / n) if n >= 2 else None)
            errs = [r.get(f"{k}_error") for r in done]
            p[f"{k}_block_error"] = (math.sqrt(sum(e * e for e in errs)) / n
                                     if n and len(errs) == n and all(_number(e) for e in errs) else None)
        out.append(p)
    return out


def plot_axes(c: Campaign) -> tuple[str, list[str]]:
    """The x key of the plots and the keys whose values make separate series (the other varied
    keys, except those zipped with x: they move with it)."""
    x = c.plot_x or c.keys[0]
    return x, [k for k in c.keys if k != x and not (x in c.zipped and k in c.zipped)]


def plot(c: Campaign, rows: list[dict], pooled: list[dict]) -> list[Path]:
    """OUT/<key>.png per collected key: the key against the x grid key (plot.x, or the first
    varied key), one series per value of the other varied keys (not those zipped with x); filled symbols are the mean
    over seeds with its standard error over seeds, small open symbols each run with its own
    block error."""
    if not c.keys:
        return []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x, others = plot_axes(c)
    xs = sorted({json.dumps(r[x]) for r in rows}, key=lambda t: (not _number(json.loads(t)), json.loads(t) if _number(json.loads(t)) else t))
    numeric = all(_number(json.loads(t)) for t in xs)
    pos = (lambda v: v) if numeric else (lambda v: xs.index(json.dumps(v)))
    span = (max(json.loads(t) for t in xs) - min(json.loads(t) for t in xs)) if numeric and len(xs) > 1 else 1.0
    files = []
    for k in c.collect:
        if not any(_number(p[k]) for p in pooled):
            continue
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        series = {}
        for p in pooled:
            series.setdefault(json.dumps([p[o] for o in others]), []).append(p)
        for si, (label, ps) in enumerate(series.items()):
            ps = [p for p in ps if _number(p[k])]
            ps.sort(key=lambda p: pos(p[x]))
            name = ", ".join(f"{o.split('.', 1)[1]}={v}" for o, v in zip(others, json.loads(label))) or None
            line = ax.errorbar([pos(p[x]) for p in ps], [p[k] for p in ps],
                               yerr=[p[f"{k}_sem"] or 0.0 for p in ps], fmt="o-", ms=5, capsize=3,
                               label=(name + " " if name else "") + "mean over seeds ± s.e.")
            color = line[0].get_color()
            runs = [r for r in rows if r["status"] == "done" and _number(r[k])
                    and json.dumps([r[o] for o in others]) == label]
            seeds = sorted({r["seed"] for r in runs})
            dx = 0.006 * span
            ax.errorbar([pos(r[x]) + dx * (seeds.index(r["seed"]) - (len(seeds) - 1) / 2 + 0.5 * (len(seeds) == 1)) for r in runs],
                        [r[k] for r in runs],
                        yerr=[r.get(f"{k}_error") or 0.0 for r in runs], fmt="o", mfc="none", ms=3,
                        capsize=1.5, lw=0.7, color=color, alpha=0.7,
                        label="each run ± its block error" if si == 0 else None)
        if not numeric:
            ax.set_xticks(range(len(xs)), [json.loads(t) if isinstance(json.loads(t), str) else t for t in xs])
        ax.set_xlabel(x)
        ax.set_ylabel(k)
        ax.set_title(f"{c.path.stem}: {k}")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        f = c.out / f"{k}.png"
        fig.savefig(f, dpi=120)
        plt.close(fig)
        files.append(f)
    return files


# ----------------------------------------------------------------------------------------------
# Running
# ----------------------------------------------------------------------------------------------

def _report(c: Campaign, infos: list[dict]) -> int:
    print_status(c, infos, out=sys.stderr)
    n = {s: sum(1 for i in infos if i["state"] == s) for s in STATES}
    if n["failed"]:
        return EXIT_FAILED
    if n["pending"] or n["running"]:
        return EXIT_PENDING
    return 0


def run(c: Campaign, jobs: int | None = None, executor: str | None = None, retry_failed: bool = False,
        wait: bool = False, hardbody: str | None = None) -> int:
    """Runs what is left of the campaign (the command `hardbody campaign CAMPAIGN.toml`); writes
    results.csv and the plots; returns the exit status (0: every run done)."""
    hb = hardbody or hardbody_binary()
    etype = executor or c.executor["type"]
    c.out.mkdir(parents=True, exist_ok=True)
    try:
        lock = ex.lock_campaign(c.out)
    except ex.CampaignBusy as e:
        say(str(e))
        return EXIT_BAD_INPUT

    def stop(sig, _frame):
        raise Stopped(sig)

    old = {s: signal.signal(s, stop) for s in (signal.SIGTERM, signal.SIGINT)}
    try:
        ex.stop_stale_engine(c.out, say)
        infos = states(c)
        todo = [i["run"] for i in infos if i["state"] == "pending" and "Slurm" not in i.get("detail", "")
                or (retry_failed and i["state"] == "failed")]
        done = sum(1 for i in infos if i["state"] == "done")
        if not todo:
            say(f"nothing to run ({done} of {len(c.runs)} done)")
        elif etype == "local":
            njobs = jobs or c.executor.get("jobs", 1)
            say(f"{len(todo)} run(s) to go ({done} done already) on {njobs} core(s) with Snakemake")
            seen = {}

            def poll():
                for i in states(c):
                    s, name = i["state"], i["run"].name
                    if seen.get(name, s) != s or (name not in seen and s == "running"):
                        msg = f"{s}: {name}"
                        if s == "failed":
                            msg += f" (exit {i['status'].get('exit')}): {i['status'].get('message', '')}"
                        say(msg)
                    seen[name] = s

            rc = ex.run_local(c, todo, hb, njobs, say, poll)
            if rc >= 128:
                say(f"stopped by signal {rc - 128}; the interrupted runs resume when the campaign is run again")
                results(c)
                return rc
        else:
            ex.submit_slurm(c, todo, hb, say)
            if wait:
                import time
                while ex.slurm_queued(c.out):
                    time.sleep(5)
        infos = states(c)
        results(c)
        say(f"results: {c.out / 'results.csv'}")
        return _report(c, infos)
    except Stopped as e:
        say(f"stopped by signal {e.signal}")
        return 128 + e.signal
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        os.close(lock)


def main(argv: list[str]) -> int:
    if argv[:1] == ["_job"]:
        return ex.job_main(argv[1:])
    import argparse
    p = argparse.ArgumentParser(prog="hardbody campaign", description=__doc__.split("\n\n")[0],
                                epilog="docs/campaigns.md")
    p.add_argument("action", nargs="?", choices=["run", "status", "results"], default=None)
    p.add_argument("campaign", nargs="?")
    p.add_argument("--jobs", "-j", type=int, help="local executor: runs at once (default executor.jobs)")
    p.add_argument("--executor", choices=["local", "slurm"], help="override executor.type")
    p.add_argument("--retry-failed", action="store_true", help="run failed runs again")
    p.add_argument("--wait", action="store_true", help="slurm: wait until the array job has left the queue")
    if argv and argv[0] not in ("run", "status", "results") and not argv[0].startswith("-"):
        argv = ["run", *argv]
    a = p.parse_args(argv)
    if a.campaign is None:
        say("error: give a campaign file: hardbody campaign [status|results] CAMPAIGN.toml (docs/campaigns.md)")
        return EXIT_BAD_INPUT
    if a.jobs is not None and a.jobs < 1:
        say("error: --jobs: expected an integer >= 1")
        return EXIT_BAD_INPUT
    try:
        c = load(a.campaign)
    except CampaignError as e:
        say(f"error: {e}")
        return EXIT_BAD_INPUT
    if a.executor:
        c.executor["type"] = a.executor
    if a.action == "status":
        print_status(c, states(c))
        return 0
    if a.action == "results":
        results(c)
        print(c.out / "results.csv")
        return 0
    return run(c, jobs=a.jobs, retry_failed=a.retry_failed, wait=a.wait)


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except KeyboardInterrupt:
        sys.exit(130)
