#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the tests of deploy/slurm/
# and for trying the scripts without a cluster: munged, slurmctld and slurmd
# from Debian's munge and slurm-wlm, everything (key, slurm.conf, state,
# spool, logs, sockets) under DIR, on free ports, this machine the only
# node with `nproc` CPUs. Needs root (SlurmUser=root).
#
# Usage: deploy/slurm/local_cluster.sh start DIR   # then: export SLURM_CONF=DIR/slurm.conf
#        deploy/slurm/local_cluster.sh stop DIR    # stops the daemons started in DIR
set -euo pipefail

usage() { sed -n '2,10p' "${BASH_SOURCE[0]}"; }
[[ $# -eq 2 ]] || { usage >&2; exit 2; }
action="$1"
dir="$(mkdir -p "$2" && cd "$2" && pwd)"

free_port() {
  python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}

stop_pidfile() {
  local file="$1" pid
  [[ -s "${file}" ]] || return 0
  pid="$(cat "${file}")"
  if kill -0 "${pid}" 2>/dev/null; then
    kill "${pid}" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "${pid}" 2>/dev/null || break; sleep 0.1; done
    kill -9 "${pid}" 2>/dev/null || true
  fi
  rm -f "${file}"
}

stop() {
  # Jobs still running would outlive slurmd as orphaned slurmstepd's.
  if [[ -f "${dir}/slurm.conf" ]] && [[ -s "${dir}/slurmctld.pid" ]]; then
    SLURM_CONF="${dir}/slurm.conf" timeout 10 scancel --full --quiet \
      --user="$(id -un)" 2>/dev/null || true
    sleep 1
  fi
  stop_pidfile "${dir}/slurmd.pid"
  stop_pidfile "${dir}/slurmctld.pid"
  stop_pidfile "${dir}/munged.pid"
  pkill -f "slurmstepd.*${dir}" 2>/dev/null || true
}

wait_for() {  # WHAT SECONDS COMMAND...
  local what="$1" seconds="$2"; shift 2
  for _ in $(seq $((seconds * 5))); do
    "$@" >/dev/null 2>&1 && return 0
    sleep 0.2
  done
  echo "local_cluster.sh: ${what} did not come up within ${seconds} s; its log:" >&2
  tail -n 20 "${dir}/${what}.log" >&2 2>/dev/null || true
  stop
  exit 1
}

start() {
  [[ "$(id -u)" -eq 0 ]] || { echo "local_cluster.sh: needs root (the daemons run as SlurmUser=root)" >&2; exit 1; }
  for tool in munged mungekey slurmctld slurmd sinfo; do
    command -v "${tool}" >/dev/null || { echo "local_cluster.sh: ${tool} is missing (deploy/setup.sh installs munge and slurm-wlm)" >&2; exit 1; }
  done
  stop
  mkdir -p "${dir}/state" "${dir}/spool" "${dir}/munge"
  chmod 700 "${dir}/munge"
  rm -f "${dir}/munge/munge.key"
  mungekey --create --keyfile="${dir}/munge/munge.key" >/dev/null
  chmod 400 "${dir}/munge/munge.key"
  munged --force --key-file="${dir}/munge/munge.key" \
    --socket="${dir}/munge/munge.sock" --pid-file="${dir}/munged.pid" \
    --log-file="${dir}/munged.log" --seed-file="${dir}/munge/munge.seed"
  wait_for munged 10 test -S "${dir}/munge/munge.sock"

  local node cpus memory
  node="$(hostname -s)"
  cpus="$(nproc)"
  memory="$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)"
  cat > "${dir}/slurm.conf" <<CONF
# Written by deploy/slurm/local_cluster.sh: one node, this machine.
ClusterName=vantage-local
SlurmctldHost=${node}(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# cred_expire: a requeued job waits this long before it may start again
# (default 120 s).
AuthInfo=socket=${dir}/munge/munge.sock,cred_expire=10
StateSaveLocation=${dir}/state
SlurmdSpoolDir=${dir}/spool
SlurmctldPidFile=${dir}/slurmctld.pid
SlurmdPidFile=${dir}/slurmd.pid
SlurmctldLogFile=${dir}/slurmctld.log
SlurmdLogFile=${dir}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
SwitchType=switch/none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
MailProg=/bin/true
# Requeued jobs start again soon (the default waits for the next pass).
SchedulerParameters=bf_interval=5
NodeName=${node} NodeAddr=127.0.0.1 CPUs=${cpus} RealMemory=${memory} State=UNKNOWN
PartitionName=local Nodes=${node} Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="${dir}/slurm.conf"
  slurmctld -f "${SLURM_CONF}" -L "${dir}/slurmctld.log"
  wait_for slurmctld 30 scontrol ping
  slurmd -f "${SLURM_CONF}" -L "${dir}/slurmd.log"
  wait_for slurmd 30 bash -c "sinfo --noheader --states=idle --format=%n | grep -q ."
  echo "local_cluster.sh: Slurm is up (node ${node}, ${cpus} CPUs); export SLURM_CONF=${SLURM_CONF}"
}

case "${action}" in
  start) start ;;
  stop) stop ;;
  *) usage >&2; exit 2 ;;
esac
