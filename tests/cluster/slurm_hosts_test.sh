#!/usr/bin/env bash
# Slurm across hosts: on tests/cluster/hosts.sh's namespace hosts, slurmctld
# on vc-learner and a slurmd on every host (its own NodeName and address),
# one munge key (munged's socket is a file every host sees), and
# `sbatch --nodes=3 deploy/slurm/train.sbatch` trains InvertedPendulum with
# the learner on the job's first node and the actors on the others, to a
# mean return of 900.
#
#   slurm_hosts_test.sh VANTAGE   exit 0: passed, 77: namespaces unavailable
set -uo pipefail

readonly VANTAGE=$(realpath "$1")
readonly ROOT="$(cd "$(dirname "$(realpath "$0")")/../.." && pwd)"
readonly HOSTS="$ROOT/tests/cluster/hosts.sh"
readonly WORK=$(mktemp -d /tmp/vantage-slurm-hosts.XXXXXX)

cleanup() {
  "$HOSTS" down >/dev/null 2>&1
  [ -s "$WORK/munged.pid" ] && kill "$(cat "$WORK/munged.pid")" 2>/dev/null
  [ "${KEEP:-0}" = 1 ] || rm -rf "$WORK"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for log in "$WORK"/*.log "$WORK"/run/slurm/*.out "$WORK"/*.out; do
    [ -f "$log" ] && { echo "--- $log"; tail -n 15 "$log"; }
  done
  exit 1
}

if ! "$HOSTS" up 4 >"$WORK/hosts.log" 2>&1; then
  grep -q "hosts.sh:" "$WORK/hosts.log" && { echo "SKIP: $(cat "$WORK/hosts.log")"; exit 77; }
  fail "hosts.sh up"
fi
for tool in munged mungekey slurmctld slurmd sbatch; do
  command -v "$tool" >/dev/null || fail "$tool is missing (deploy/setup.sh --tests installs slurm-wlm and munge)"
done

mkdir -p "$WORK/munge" "$WORK/state" "$WORK/spool"
chmod 700 "$WORK/munge"
mungekey --create --keyfile="$WORK/munge/munge.key" >/dev/null
chmod 400 "$WORK/munge/munge.key"
munged --force --key-file="$WORK/munge/munge.key" --socket="$WORK/munge/munge.sock" \
  --pid-file="$WORK/munged.pid" --log-file="$WORK/munged.log" \
  --seed-file="$WORK/munge/munge.seed" || fail "munged did not start"

nodes=(vc-learner vc-actor1 vc-actor2 vc-actor3)
{
  echo "ClusterName=vantage-hosts"
  echo "SlurmctldHost=vc-learner($("$HOSTS" address vc-learner))"
  echo "SlurmctldPort=6817"
  echo "SlurmdPort=6818"
  echo "SlurmUser=root"
  echo "SlurmdUser=root"
  echo "AuthType=auth/munge"
  echo "CredType=cred/munge"
  echo "AuthInfo=socket=$WORK/munge/munge.sock"
  echo "StateSaveLocation=$WORK/state"
  # Every node's own spool, pid file and log (%n: its NodeName).
  echo "SlurmdSpoolDir=$WORK/spool/%n"
  echo "SlurmdPidFile=$WORK/slurmd-%n.pid"
  echo "SlurmdLogFile=$WORK/slurmd-%n.log"
  echo "SlurmctldPidFile=$WORK/slurmctld.pid"
  echo "SlurmctldLogFile=$WORK/slurmctld.log"
  echo "ProctrackType=proctrack/linuxproc"
  echo "TaskPlugin=task/none"
  echo "SelectType=select/cons_tres"
  echo "SelectTypeParameters=CR_Core"
  echo "SchedulerType=sched/backfill"
  echo "MpiDefault=none"
  echo "SwitchType=switch/none"
  echo "JobCompType=jobcomp/none"
  echo "AccountingStorageType=accounting_storage/none"
  echo "ReturnToService=2"
  echo "MailProg=/bin/true"
  for node in "${nodes[@]}"; do
    echo "NodeName=$node NodeAddr=$("$HOSTS" address "$node") CPUs=2 RealMemory=2000 State=UNKNOWN"
  done
  echo "PartitionName=hosts Nodes=$(IFS=,; echo "${nodes[*]}") Default=YES MaxTime=INFINITE State=UP"
} >"$WORK/slurm.conf"
export SLURM_CONF="$WORK/slurm.conf"

on() { local host=$1; shift; "$HOSTS" run "$host" env SLURM_CONF="$SLURM_CONF" "$@"; }
on vc-learner slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start"
for _ in $(seq 1 100); do on vc-learner scontrol ping >/dev/null 2>&1 && break; sleep 0.2; done
for node in "${nodes[@]}"; do
  mkdir -p "$WORK/spool/$node"
  on "$node" slurmd -f "$SLURM_CONF" || fail "slurmd on $node did not start"
done
for _ in $(seq 1 150); do
  [ "$(on vc-learner sinfo --noheader --states=idle --format=%n 2>/dev/null | wc -l)" -ge 4 ] && break
  sleep 0.2
done
idle=$(on vc-learner sinfo --noheader --states=idle --format=%n 2>/dev/null | sort | tr '\n' ' ')
echo "slurm hosts: idle nodes: $idle"
[ "$(echo $idle | wc -w)" -ge 4 ] || fail "not every slurmd registered (idle: $idle)"

cd "$WORK"
job=$(on vc-learner sbatch --parsable --overcommit --nodes=3 --ntasks=3 \
  --ntasks-per-node=1 --output="$WORK/job-%j.out" \
  --export=ALL,VANTAGE_BIN="$VANTAGE",VANTAGE_RUN_DIR="$WORK/run",VANTAGE_TRAIN_ARGS="--env=InvertedPendulum --algo=ppo --estimator=maxabs --rho=0.4 --horizon=1024 --steps=200000 --seed=1" \
  "$ROOT/deploy/slurm/train.sbatch") || fail "sbatch refused the job"
echo "slurm hosts: job $job submitted"
for _ in $(seq 1 1800); do
  state=$(on vc-learner squeue --noheader --jobs="$job" --format=%T 2>/dev/null)
  [ -z "$state" ] && break
  sleep 0.2
done
[ -z "$state" ] || fail "job $job still $state after 6 minutes"
learner_host=$(grep -o "learner at [^:]*" "$WORK/job-$job.out" | head -1 | cut -d' ' -f3)
actor_hosts=$(cat "$WORK/run/slurm/"actor-*.host 2>/dev/null | sort | tr '\n' ' ')
echo "slurm hosts: learner on $learner_host, actors on $actor_hosts"
[ -n "$learner_host" ] || fail "the job never said where its learner was"
for host in $actor_hosts; do
  [ "$host" != "$learner_host" ] || fail "an actor ran on the learner's node $host"
done
[ "$(echo $actor_hosts | wc -w)" -ge 2 ] || fail "fewer than two actors ran"
best=$(python3 - "$WORK/run/progress.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print(max(float(r["mean_return"]) for r in rows if r["mean_return"]))
PY
) || fail "no progress.csv"
echo "slurm hosts: best mean return $best"
python3 -c "import sys; sys.exit(0 if float('$best') >= 900 else 1)" ||
  fail "best mean return $best < 900"
echo "PASS"
