"""Running a campaign's runs: one job (the wrapper around one `hardbody run`), the local executor
(Snakemake on N cores) and the Slurm executor (a generated `sbatch --array` script).

No scheduling happens here: Snakemake decides what runs when on one machine, Slurm on a cluster.
This module only says what one job is, records how it ended, and hands the list to the engine.

Files under the campaign's `out` directory:
    runs/NAME/                 the run directory of `hardbody run` (its lock says it is running)
    logs/NAME.log              stderr of every attempt, each headed by its command
    status/NAME.json           how the last attempt ended: exit, message, reproducer, attempts
    .campaign/                 the engine's files (run list, Snakefile, Slurm scripts, lock)
"""

from __future__ import annotations

import ctypes
import datetime
import fcntl
import json
import os
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

SCRIPT = Path(__file__).resolve().parent / "hardbody_campaign.py"
PYTHON = "/usr/bin/python3"
INTERRUPTED_EXITS = {128 + signal.SIGINT, 128 + signal.SIGTERM}


def now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def write_json_atomic(path: Path, obj) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + f".tmp{os.getpid()}")
    tmp.write_text(json.dumps(obj, indent=1) + "\n")
    os.replace(tmp, path)


def run_spec(campaign, run, hardbody: str) -> dict:
    """Everything a job needs to know about its run (written to the engine's run list)."""
    return {"index": run.index, "name": run.name, "params": run.params, "seed": run.seed,
            "dir": str(campaign.run_dir(run)), "command": campaign.command(run, hardbody),
            "log": str(campaign.out / "logs" / f"{run.name}.log"),
            "status": str(campaign.out / "status" / f"{run.name}.json")}


def last_message(text: str) -> str:
    """The error line of a hardbody stderr (its last line that starts with 'hardbody:')."""
    lines = [l for l in text.splitlines() if l.startswith("hardbody:")]
    return lines[-1] if lines else (text.strip().splitlines() or [""])[-1]


# ----------------------------------------------------------------------------------------------
# One job: `hardbody run` (resumed when its directory already holds the run), how it ended.
# ----------------------------------------------------------------------------------------------

def run_job(spec: dict, slurm: bool = False) -> int:
    """Runs one run to its end or to a stop request; records the outcome in its status file.

    SIGTERM/SIGINT are passed on to hardbody, which writes its checkpoint and exits 128 + signal.
    Under Slurm, hardbody is a job step (srun), so `scancel --signal=TERM` reaches it; SIGUSR1
    (sent before the time limit by `--signal=B:USR1@grace`) and SIGTERM (pre-emption) are passed
    on the same way, and an interrupted run asks Slurm to requeue its array task, which then
    resumes from the checkpoint. Returns the exit status of hardbody."""
    run_dir = Path(spec["dir"])
    resume = (run_dir / "config.resolved.toml").exists()
    cmd = list(spec["command"]) + (["--resume"] if resume else [])
    launch = cmd
    if slurm:
        launch = ["srun", "--ntasks=1", "--nodes=1", "--quiet", "--kill-on-bad-exit=1", *cmd]
    log = Path(spec["log"])
    log.parent.mkdir(parents=True, exist_ok=True)
    status_path = Path(spec["status"])
    try:
        previous = json.loads(status_path.read_text())
    except (OSError, ValueError):
        previous = {}
    got = {"signal": 0}
    child = None

    def forward(sig, _frame):
        got["signal"] = sig
        if child is None or child.poll() is not None:
            return
        if slurm:
            # srun cancels its step (SIGKILL) on SIGTERM; the step's own SIGTERM comes from
            # Slurm (in the background: scancel may wait while the job is being changed)
            subprocess.Popen(["scancel", "--quiet", "--signal=TERM", os.environ["SLURM_JOB_ID"]],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        else:
            child.send_signal(signal.SIGTERM if sig == signal.SIGUSR1 else sig)

    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1):
        signal.signal(s, forward)
    with open(log, "a") as lf:
        where = f" (Slurm job {os.environ.get('SLURM_JOB_ID')}, array task {os.environ.get('SLURM_ARRAY_TASK_ID')}, restart {os.environ.get('SLURM_RESTART_COUNT', '0')})" if slurm else ""
        lf.write(f"== {now()}{where}: {shlex.join(cmd)}\n")
        lf.flush()
        child = subprocess.Popen(launch, stdout=lf, stderr=subprocess.PIPE, text=True)
        if got["signal"]:  # a stop request that came while it was starting
            forward(got["signal"], None)
        err = ""
        while True:
            try:
                err = child.communicate()[1]
                break
            except InterruptedError:
                continue
        lf.write(err)
        rc = child.returncode
        lf.write(f"== exit {rc}\n")
    if rc < 0:  # killed by a signal it could not catch (SIGKILL): the next attempt resumes
        rc = 128 - rc
    state = ("done" if rc == 0 else "failed" if rc in (2, 3) else "interrupted")
    reproducer = shlex.join(list(spec["command"]) + (["--resume"] if (run_dir / "checkpoint.gsd").exists() else []))
    write_json_atomic(status_path, {
        "name": spec["name"], "state": state, "exit": rc, "message": last_message(err) if rc else "",
        "reproducer": reproducer, "attempts": previous.get("attempts", 0) + 1, "time": now(),
        "slurm_job": os.environ.get("SLURM_JOB_ID") if slurm else None})
    if slurm and state == "interrupted" and slurm_state(os.environ["SLURM_JOB_ID"]) == "RUNNING":
        # signalled while the job goes on (scancel --signal=TERM, the time-limit warning): back
        # into the queue; the requeued task resumes from the checkpoint just written. A job
        # cancelled (scancel) is not requeued; a pre-empted one is requeued by Slurm itself.
        subprocess.run(["scontrol", "requeue", os.environ["SLURM_JOB_ID"]], check=False)
    return rc


def slurm_state(job: str) -> str:
    r = subprocess.run(["squeue", "-h", "-j", job, "-o", "%T"], capture_output=True, text=True)
    return r.stdout.strip()


def job_main(argv: list[str]) -> int:
    """`hardbody_campaign.py _job [--slurm] RUNLIST KEY`: KEY is a run name, or with --slurm an
    array task id (the index in the submission's run list)."""
    slurm = argv[:1] == ["--slurm"]
    if slurm:
        argv = argv[1:]
    runlist, key = argv
    specs = json.loads(Path(runlist).read_text())
    if slurm:
        spec = specs[int(key)]
    else:
        spec = next(s for s in specs if s["name"] == key)
    return run_job(spec, slurm=slurm)


# ----------------------------------------------------------------------------------------------
# The campaign lock and the engine left behind by a killed driver
# ----------------------------------------------------------------------------------------------

class CampaignBusy(Exception):
    pass


def lock_campaign(out: Path):
    """Locks OUT/.campaign/lock for this process (flock: released when it dies, even by SIGKILL)."""
    d = out / ".campaign"
    d.mkdir(parents=True, exist_ok=True)
    fd = os.open(d / "lock", os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise CampaignBusy(f"{out}: in use by another 'hardbody campaign' process") from None
    return fd


def _group_members(pgid: int) -> list[int]:
    """Processes of process group pgid whose session is also pgid (the engine's own session)."""
    pids = []
    for p in Path("/proc").iterdir():
        if not p.name.isdigit():
            continue
        try:
            stat = (p / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        # a zombie is already gone (its parent, maybe an init that never reaps, has not waited)
        if fields[0] != "Z" and int(fields[2]) == pgid and int(fields[3]) == pgid:
            pids.append(int(p.name))
    return pids


def stop_stale_engine(out: Path, say) -> None:
    """A driver killed by SIGKILL leaves its engine and jobs running (in their own session). They
    are stopped the way hardbody expects (SIGTERM: checkpoint, exit) before anything starts again."""
    rec = out / ".campaign" / "engine.json"
    try:
        pgid = json.loads(rec.read_text())["pgid"]
    except (OSError, ValueError, KeyError):
        return
    members = _group_members(pgid)
    if members:
        say(f"stopping {len(members)} process(es) left running by a previous campaign process (group {pgid})")
        try:
            os.killpg(pgid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        for _ in range(1200):
            if not _group_members(pgid):
                break
            time.sleep(0.1)
        else:
            os.killpg(pgid, signal.SIGKILL)
    rec.unlink(missing_ok=True)


def _die_with_parent():
    # the engine gets SIGTERM when the driver dies (even by SIGKILL): no new job starts after it
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


# ----------------------------------------------------------------------------------------------
# Local executor: Snakemake
# ----------------------------------------------------------------------------------------------

SNAKEFILE = """\
# Generated by hardbody campaign (python/campaign_exec.py): one rule, one job per run.
RUNLIST = {runlist!r}
NAMES = {names!r}

rule all:
    input: expand("runs/{{name}}/summary.json", name=NAMES)

rule run:
    output: "runs/{{name}}/summary.json"
    threads: 1
    shell: "{python} {script} _job {{RUNLIST:q}} {{wildcards.name:q}}"
"""


def run_local(campaign, todo: list, hardbody: str, jobs: int, say, poll) -> int:
    """Runs the runs `todo` with Snakemake on `jobs` cores; returns Snakemake's exit status, or
    128 + signal when the campaign itself was asked to stop (its runs then stop with a checkpoint)."""
    eng = campaign.out / ".campaign"
    runlist = eng / "runs.json"
    write_json_atomic(runlist, [run_spec(campaign, r, hardbody) for r in todo])
    (eng / "Snakefile").write_text(SNAKEFILE.format(runlist=str(runlist), names=[r.name for r in todo],
                                                    python=PYTHON, script=str(SCRIPT)))
    cmd = [PYTHON, "-m", "snakemake", "--snakefile", str(eng / "Snakefile"), "--directory",
           str(campaign.out), "--cores", str(jobs), "--keep-going", "--rerun-incomplete", "--nolock",
           "--rerun-triggers", "mtime", "--latency-wait", "0"]
    env = dict(os.environ, HARDBODY=hardbody)
    stop = {"signal": 0}
    engine = None

    def on_signal(sig, _frame):
        stop["signal"] = sig
        if engine is not None:
            try:  # the engine and every job: each hardbody writes its checkpoint and exits
                os.killpg(engine.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    try:
        with open(eng / "snakemake.log", "a") as log:
            log.write(f"== {now()}: {shlex.join(cmd)}\n")
            log.flush()
            engine = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env,
                                      start_new_session=True, preexec_fn=_die_with_parent)
        write_json_atomic(eng / "engine.json", {"pgid": engine.pid, "driver": os.getpid()})
        if stop["signal"]:
            os.killpg(engine.pid, signal.SIGTERM)
        while engine.poll() is None:
            poll()
            time.sleep(0.5)
        # the engine is gone; wait for its jobs (they are in its group)
        while _group_members(engine.pid):
            time.sleep(0.1)
    finally:
        for s, h in old.items():
            signal.signal(s, h)
    (eng / "engine.json").unlink(missing_ok=True)
    poll()
    if stop["signal"]:
        return 128 + stop["signal"]
    return engine.returncode


# ----------------------------------------------------------------------------------------------
# Slurm executor: a standard `sbatch --array` script
# ----------------------------------------------------------------------------------------------

def slurm_script(campaign, runlist: Path, n: int, hardbody: str, ex: dict) -> str:
    out = campaign.out
    lines = ["#!/bin/bash",
             f"#SBATCH --job-name=hb-{campaign.path.stem}",
             f"#SBATCH --array=0-{n - 1}" + (f"%{ex['max_parallel']}" if "max_parallel" in ex else ""),
             "#SBATCH --ntasks=1",
             "#SBATCH --cpus-per-task=1",
             "#SBATCH --requeue",
             "#SBATCH --open-mode=append",
             f"#SBATCH --signal=B:USR1@{int(ex.get('grace', 60))}",
             f"#SBATCH --output={out}/logs/slurm-%A_%a.out",
             f"#SBATCH --chdir={out}"]
    if "time" in ex:
        lines.append(f"#SBATCH --time={ex['time']}")
    if "partition" in ex:
        lines.append(f"#SBATCH --partition={ex['partition']}")
    if "memory" in ex:
        lines.append(f"#SBATCH --mem={ex['memory']}")
    if "account" in ex:
        lines.append(f"#SBATCH --account={ex['account']}")
    for o in ex.get("sbatch_options", []):
        lines.append(f"#SBATCH {o}")
    lines += ["# Each array task is one run: `hardbody run` as a job step (so that scancel --signal",
              "# reaches it), resumed from its checkpoint when the run directory holds one. SIGUSR1",
              "# (grace seconds before the time limit) or SIGTERM (pre-emption, scancel --signal=TERM)",
              "# make hardbody write its checkpoint; the task then requeues itself.",
              f"export HARDBODY={shlex.quote(hardbody)}",
              f"exec {PYTHON} {shlex.quote(str(SCRIPT))} _job --slurm {shlex.quote(str(runlist))} \"$SLURM_ARRAY_TASK_ID\"",
              ""]
    return "\n".join(lines)


def slurm_queued(out: Path) -> dict:
    """Run name -> Slurm state of this campaign's array tasks still in the queue."""
    subs = sorted((out / ".campaign" / "slurm").glob("*.job.json"))
    if not subs:
        return {}
    names = {}
    jobids = []
    for s in subs:
        rec = json.loads(s.read_text())
        jobids.append(str(rec["job"]))
        for i, name in enumerate(rec["names"]):
            names[f"{rec['job']}_{i}"] = name
    try:
        q = subprocess.run(["squeue", "-h", "-r", "-j", ",".join(jobids), "-o", "%i %T"],
                           capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return {}
    res = {}
    for line in q.stdout.splitlines():
        parts = line.split()
        if len(parts) == 2 and parts[0] in names:
            res[names[parts[0]]] = parts[1].lower()
    return res


def submit_slurm(campaign, todo: list, hardbody: str, say) -> str:
    """Writes and submits one array job for the runs `todo`; returns the Slurm job id."""
    stamp = datetime.datetime.now().strftime("%Y%m%d-%H%M%S-%f")
    d = campaign.out / ".campaign" / "slurm"
    d.mkdir(parents=True, exist_ok=True)
    (campaign.out / "logs").mkdir(parents=True, exist_ok=True)
    runlist = d / f"{stamp}.runs.json"
    write_json_atomic(runlist, [run_spec(campaign, r, hardbody) for r in todo])
    script = d / f"{stamp}.sbatch"
    script.write_text(slurm_script(campaign, runlist, len(todo), hardbody, campaign.executor))
    r = subprocess.run(["sbatch", "--parsable", str(script)], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"sbatch {script} failed (exit {r.returncode}): {r.stderr.strip()}")
    job = r.stdout.strip().split(";")[0]
    write_json_atomic(d / f"{stamp}.job.json", {"job": job, "script": str(script), "names": [x.name for x in todo]})
    say(f"submitted {len(todo)} run(s) as Slurm array job {job} ({script})")
    return job
