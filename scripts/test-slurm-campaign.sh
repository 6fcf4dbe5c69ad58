#!/usr/bin/env bash
# Campaigns on Slurm (issue 14), on the one-node cluster of scripts/slurm-local.sh:
#  1. the small campaign examples/campaigns/spheres-small.toml (12 runs) as one job array; one
#     running array task gets `scancel --signal=TERM`: it must checkpoint, requeue itself and
#     resume (its log shows exit 143, then a restart that ends with exit 0);
#  2. a one-run campaign of the same spheres whose run needs more than its time limit (2
#     minutes): warned by SIGUSR1 (--signal=B:USR1@60) it checkpoints, requeues and resumes;
#  3. both give results identical bit for bit to the local executor's (python/campaign_compare.py).
# Not part of `make test` (it starts daemons); `scripts/validate.sh slurm` calls it.
# Environment: HB (binary, default build/apps/hardbody/hardbody), SLURM_WORK (default
# /tmp/hardbody-slurm-campaign; emptied first). Takes about 5 minutes on 2 cores.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
HB=$(realpath "${HB:-$root/build/apps/hardbody/hardbody}")
[ -x "$HB" ] || { echo "build first: make build (or set HB)" >&2; exit 1; }
work=${SLURM_WORK:-/tmp/hardbody-slurm-campaign}
"$root/scripts/slurm-local.sh" >/dev/null
rm -rf "$work"
mkdir -p "$work/local" "$work/slurm"
fail() { echo "FAIL: $*" >&2; exit 1; }

# the campaigns: the small one as it is (local) and with a Slurm executor; the long run
src=$root/examples/campaigns
for d in local slurm; do
  cp "$src/spheres-small-base.toml" "$work/$d/"
  sed -e '/^\[executor\]/,$d' -e 's/^out = .*/out = "small"/' "$src/spheres-small.toml" > "$work/$d/small.toml"
  { sed '/^\[executor\]/,$d' "$src/spheres-small.toml" |
      sed -e 's/^out = .*/out = "long"/' -e 's/^seeds = .*/seeds = [7]/' -e '/^"system.packing_fraction"/d'
    printf '[set]\n"system.packing_fraction" = 0.45\n"run.time" = 12000.0\n'; } > "$work/$d/long.toml"
done
printf '[executor]\ntype = "local"\njobs = 2\n' | tee -a "$work/local/small.toml" >> "$work/local/long.toml"
printf '[executor]\ntype = "slurm"\npartition = "debug"\ntime = "00:10:00"\nmemory = "500M"\n' >> "$work/slurm/small.toml"
printf '[executor]\ntype = "slurm"\npartition = "debug"\ntime = "2"\nmemory = "500M"\ngrace = 60\n' >> "$work/slurm/long.toml"

echo "== Slurm: submit both campaigns" >&2
for c in long small; do  # exit 4: submitted, runs remain
  rc=0; (cd "$work/slurm" && "$HB" campaign $c.toml) || rc=$?
  [ $rc = 4 ] || fail "submitting $c.toml: exit $rc"
done
small_job=$(/usr/bin/python3 -c "import json,glob; print(json.load(open(sorted(glob.glob('$work/slurm/small/.campaign/slurm/*.job.json'))[-1]))['job'])")
long_job=$(/usr/bin/python3 -c "import json,glob; print(json.load(open(sorted(glob.glob('$work/slurm/long/.campaign/slurm/*.job.json'))[-1]))['job'])")
echo "array jobs: small $small_job, long $long_job" >&2

# scancel --signal=TERM one array task while its run is running (retried on another task when
# the run was over before the signal arrived)
term_task=""
for _ in $(seq 600); do
  for t in $(squeue -h -r -j "$small_job" -t RUNNING -o %i); do
    idx=${t#*_}
    name=$(/usr/bin/python3 -c "import json,glob; print(json.load(open(sorted(glob.glob('$work/slurm/small/.campaign/slurm/*.job.json'))[-1]))['names'][$idx])")
    if [ -f "$work/slurm/small/runs/$name/checkpoint.gsd" ] && [ ! -f "$work/slurm/small/runs/$name/summary.json" ]; then
      # (in the background: scancel keeps retrying while the requeued task cannot be altered)
      scancel --signal=TERM "$t" 2>/dev/null & scancel_pid=$!
      for _ in $(seq 300); do  # until the attempt has ended (srun passes the signal on)
        grep -q "== exit" "$work/slurm/small/logs/$name.log" 2>/dev/null && break
        sleep 0.2
      done
      kill "$scancel_pid" 2>/dev/null || true
      if grep -q "== exit 143" "$work/slurm/small/logs/$name.log"; then term_task=$name; break 2; fi
    fi
  done
  [ -z "$(squeue -h -r -j "$small_job")" ] && break
  sleep 0.2
done
[ -n "$term_task" ] || fail "no array task of job $small_job was caught running"
echo "scancel --signal=TERM: $term_task stopped with its checkpoint" >&2

echo "== local executor: the same campaigns" >&2
(cd "$work/local" && "$HB" campaign small.toml && "$HB" campaign long.toml)

echo "== waiting for the Slurm jobs" >&2
for _ in $(seq 1800); do
  [ -z "$(squeue -h -r -j "$small_job,$long_job")" ] && break
  sleep 1
done
[ -z "$(squeue -h -r -j "$small_job,$long_job")" ] || fail "jobs still queued after 30 minutes"
(cd "$work/slurm" && "$HB" campaign status small.toml && "$HB" campaign status long.toml) >&2

# the TERM'ed task: exit 143, then requeued (a restart) and resumed to exit 0
log=$work/slurm/small/logs/$term_task.log
grep -q "restart 1" "$log" || fail "$term_task was not requeued: $log"
grep -A2 "restart 1" "$log" | grep -q -- "--resume" || fail "$term_task did not resume: $log"
tail -n 1 "$log" | grep -q "== exit 0" || fail "$term_task did not finish: $log"
# the long run: stopped by the time-limit warning at least once, then resumed to its end
log=$work/slurm/long/logs/seed=7.log
[ "$(grep -c "== exit 143" "$log")" -ge 1 ] || fail "the long run never reached its time limit: $log"
grep -q "restart 1" "$log" || fail "the long run was not requeued: $log"
tail -n 1 "$log" | grep -q "== exit 0" || fail "the long run did not finish: $log"
echo "time limit: the long run was stopped $(grep -c "== exit 143" "$log") time(s) and resumed" >&2

for c in small long; do
  (cd "$work/slurm" && "$HB" campaign results $c.toml >/dev/null)
  /usr/bin/python3 "$root/python/campaign_compare.py" "$work/local/$c" "$work/slurm/$c" || fail "$c: Slurm and local runs differ"
  cmp <(cut -d, -f1-100 "$work/local/$c/results.csv") <(cut -d, -f1-100 "$work/slurm/$c/results.csv") ||
    fail "$c: results.csv differ"
done
echo "PASS: Slurm job arrays (scancel --signal=TERM, time limit) give the local executor's results" >&2
