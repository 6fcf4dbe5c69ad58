#!/usr/bin/env bash
# A single-node Slurm cluster on this machine (Debian's slurm-wlm: slurmctld + slurmd, munge for
# authentication), for scripts/test-slurm-campaign.sh and for trying `hardbody campaign` with
# executor.type = "slurm". Idempotent: installs what is missing, writes
# /etc/slurm/slurm.conf for this host (its name, CPUs and memory; one partition "debug"),
# creates the munge key once, and (re)starts only the daemons that are not running or whose
# configuration changed. Needs root (or sudo). Not part of `make test`.
#
# Usage: scripts/slurm-local.sh [stop]
set -euo pipefail
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo

if [ "${1:-}" = stop ]; then
  for d in slurmd slurmctld munged; do
    pid=$(pgrep -x "$d" || true)
    [ -n "$pid" ] && $SUDO kill "$pid" && echo "stopped $d ($pid)"
  done
  exit 0
fi

pkgs=(slurm-wlm slurm-client munge)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# munge: one key, its daemon
if [ ! -s /etc/munge/munge.key ]; then
  $SUDO mkdir -p /etc/munge
  $SUDO dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
fi
$SUDO chown munge:munge /etc/munge/munge.key
$SUDO chmod 400 /etc/munge/munge.key
$SUDO mkdir -p /run/munge /var/log/munge /var/lib/munge
$SUDO chown munge:munge /run/munge /var/log/munge /var/lib/munge
if ! pgrep -x munged >/dev/null; then
  if [ -n "$SUDO" ]; then sudo -u munge /usr/sbin/munged; else runuser -u munge -- /usr/sbin/munged; fi
  echo "started munged" >&2
fi
munge -n | unmunge >/dev/null

# slurm.conf for this host
host=$(hostname -s)
cpus=$(nproc)
mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 ))
conf=$(cat <<CONF
# Written by hardbody scripts/slurm-local.sh: a one-node cluster on $host.
ClusterName=hardbody-local
SlurmctldHost=$host
AuthType=auth/munge
# a requeued job waits cred_expire seconds before it may start again (default 120)
AuthInfo=cred_expire=30
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
SlurmUser=root
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmdSpoolDir=/var/spool/slurmd
StateSaveLocation=/var/spool/slurmctld
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
JobRequeue=1
MinJobAge=300
SchedulerParameters=bf_interval=5,sched_min_interval=200000
KillWait=30
MpiDefault=none
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
CONF
)
$SUDO mkdir -p /etc/slurm /var/spool/slurmd /var/spool/slurmctld /var/log/slurm
changed=0
if [ "$(cat /etc/slurm/slurm.conf 2>/dev/null)" != "$conf" ]; then
  printf '%s\n' "$conf" | $SUDO tee /etc/slurm/slurm.conf >/dev/null
  changed=1
  echo "wrote /etc/slurm/slurm.conf" >&2
fi
for d in slurmctld slurmd; do
  pid=$(pgrep -x "$d" || true)
  if [ -n "$pid" ] && [ $changed = 1 ]; then
    $SUDO kill "$pid"
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    pid=""
  fi
  if [ -z "$pid" ]; then
    $SUDO /usr/sbin/$d
    echo "started $d" >&2
  fi
done
# wait until the node takes jobs
for _ in $(seq 60); do
  state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
  case "$state" in idle*|mixed*|allocated*) break ;; esac
  [ -n "$state" ] && case "$state" in down*|drain*) $SUDO scontrol update nodename="$host" state=resume 2>/dev/null || true ;; esac
  sleep 1
done
sinfo
