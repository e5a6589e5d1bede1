#!/usr/bin/env bash
# A one-node Slurm for the fleet tests, started without systemd (CI machines have none):
#   slurm_fixture.sh start DIR   munged (when no munge daemon answers), slurmctld and slurmd
#                                with their own configuration, state and ports under DIR;
#                                waits (60 s at most) until the node takes jobs
#   slurm_fixture.sh stop DIR    stops what start started, nothing else
# Tests then run sbatch with SLURM_CONF=DIR/slurm.conf. Every wait has a time limit, and a
# daemon that does not come up ends start with its log's last lines.
set -u
action=${1:-}
dir=${2:-}
if [ -z "$action" ] || [ -z "$dir" ]; then
  echo "usage: slurm_fixture.sh start|stop DIR" >&2
  exit 2
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
conf="$dir/slurm.conf"
started="$dir/started"

stop_all() {
  [ -f "$started" ] || return 0
  # Each line: a daemon's name and its pid file; only these are stopped.
  while read -r name pidfile; do
    [ -f "$pidfile" ] || continue
    pid=$(cat "$pidfile" 2>/dev/null)
    [ -n "$pid" ] || continue
    kill "$pid" 2>/dev/null
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done < <(tac "$started")
  rm -f "$started"
}

fail() {
  echo "slurm_fixture: $1" >&2
  for log in "$dir"/slurmctld.log "$dir"/slurmd.log "$dir"/munged.log; do
    [ -f "$log" ] && { echo "--- last lines of $log" >&2; tail -n 15 "$log" >&2; }
  done
  stop_all
  exit 1
}

if [ "$action" = stop ]; then
  stop_all
  echo "slurm_fixture: stopped"
  exit 0
fi
[ "$action" = start ] || { echo "slurm_fixture: unknown action '$action'" >&2; exit 2; }

for tool in slurmctld slurmd sbatch squeue sinfo munge munged; do
  command -v "$tool" >/dev/null 2>&1 || PATH="$PATH:/usr/sbin"
  command -v "$tool" >/dev/null 2>&1 ||
    fail "$tool is not installed (Debian: slurm-wlm and munge; scripts/install-deps.sh installs them)"
done
stop_all
host=$(hostname -s)
cpus=$(nproc)
# Ports of their own, so that a Slurm the machine already runs is left alone.
port=$((17000 + ($(id -u) % 1000) * 2))
mkdir -p "$dir/state" "$dir/spool"
user=$(id -un)
cat > "$conf" <<CONF
ClusterName=flexarmtest
SlurmctldHost=$host
SlurmUser=$user
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=30
KillWait=5
Waittime=0
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=fleet Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$conf"

if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  [ -f /etc/munge/munge.key ] || fail "no munge key (/etc/munge/munge.key; installing munge creates it)"
  mkdir -p /run/munge /var/log/munge /var/lib/munge
  force=""
  [ "$(id -u)" = 0 ] && force="--force"
  munged $force --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" >/dev/null 2>&1 ||
    fail "munged would not start"
  echo "munged $dir/munged.pid" >> "$started"
  for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
  munge -n 2>/dev/null | unmunge >/dev/null 2>&1 || fail "munge does not answer"
fi
slurmctld -f "$conf" >/dev/null 2>&1 || fail "slurmctld would not start"
for _ in $(seq 100); do [ -s "$dir/slurmctld.pid" ] && break; sleep 0.1; done
echo "slurmctld $dir/slurmctld.pid" >> "$started"
slurmd -f "$conf" >/dev/null 2>&1 || fail "slurmd would not start"
for _ in $(seq 100); do [ -s "$dir/slurmd.pid" ] && break; sleep 0.1; done
echo "slurmd $dir/slurmd.pid" >> "$started"
for _ in $(seq 120); do
  state=$(timeout 5 sinfo -h -N -o %T 2>/dev/null | head -n 1)
  case "$state" in idle*|mix*|alloc*) echo "slurm_fixture: node $host $state (SLURM_CONF=$conf)"; exit 0 ;; esac
  sleep 0.5
done
fail "the node did not become idle within 60 s (state: '${state:-none}')"
