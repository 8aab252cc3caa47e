#!/usr/bin/env bash
# A small cluster on this machine: Linux network namespaces on a bridge, each
# a host with its own address and, for what runs in it, its own hostname
# (a UTS namespace) and an /etc/hosts that names every host.
#
#   hosts.sh up [N]            N hosts (default 4): vc-learner, vc-actor1..N-1
#   hosts.sh run HOST CMD...   runs CMD on HOST (as HOST, resolving the others)
#   hosts.sh cut HOST          takes HOST's link down (no packets either way)
#   hosts.sh heal HOST         brings it back
#   hosts.sh kill HOST         kills every process running on HOST
#   hosts.sh down              removes all of it (also what a killed run left)
#   hosts.sh address HOST      prints HOST's address
#
# Needs root and `ip netns`; without them it exits 2 saying what is missing.
# Hosts are 10.213.0.1, .2, ... on the bridge vcbr0; nothing is routed
# beyond it, and the machine's own namespace has no address on it.
set -euo pipefail

readonly PREFIX=vc
readonly BRIDGE=${PREFIX}br0
readonly SUBNET=10.213.0
readonly STATE=/run/vantage-cluster

die() { echo "hosts.sh: $*" >&2; exit 2; }

check() {
  [ "$(id -u)" = 0 ] || die "needs root (network namespaces); run it as root or with sudo"
  command -v ip >/dev/null || die "needs ip (iproute2: apt-get install iproute2)"
  command -v nsenter >/dev/null && command -v unshare >/dev/null ||
    die "needs nsenter and unshare (util-linux)"
  ip netns list >/dev/null 2>&1 || die "ip netns does not work here (no network namespaces?)"
}

host_names() { cat "$STATE/names" 2>/dev/null || true; }

index_of() {
  local i=1 name
  for name in $(host_names); do
    [ "$name" = "$1" ] && { echo "$i"; return; }
    i=$((i + 1))
  done
  die "no host $1 (hosts: $(host_names | tr '\n' ' '))"
}

down() {
  local ns
  for ns in $(ip netns list 2>/dev/null | awk '{print $1}' | grep "^${PREFIX}-" || true); do
    # Whatever still runs there goes first: a namespace held by a process
    # would outlive its name.
    for pid in $(ip netns pids "$ns" 2>/dev/null); do kill -9 "$pid" 2>/dev/null || true; done
    ip netns delete "$ns" 2>/dev/null || true
  done
  for link in $(ip -o link show 2>/dev/null | awk -F': ' '{print $2}' | cut -d@ -f1 |
                grep "^${PREFIX}v" || true); do
    ip link delete "$link" 2>/dev/null || true
  done
  ip link delete "$BRIDGE" 2>/dev/null || true
  rm -rf "$STATE"
}

up() {
  local count=${1:-4} i name
  [ "$count" -ge 2 ] && [ "$count" -le 200 ] || die "up takes 2..200 hosts, not $count"
  down
  mkdir -p "$STATE"
  ip link add "$BRIDGE" type bridge
  ip link set "$BRIDGE" up
  : >"$STATE/names"
  printf '127.0.0.1 localhost\n' >"$STATE/hosts"
  for i in $(seq 1 "$count"); do
    if [ "$i" = 1 ]; then name=${PREFIX}-learner; else name=${PREFIX}-actor$((i - 1)); fi
    echo "$name" >>"$STATE/names"
    printf '%s.%d %s\n' "$SUBNET" "$i" "$name" >>"$STATE/hosts"
    ip netns add "$name"
    ip link add "${PREFIX}v$i" type veth peer name eth0 netns "$name"
    ip link set "${PREFIX}v$i" master "$BRIDGE" up
    ip -n "$name" addr add "$SUBNET.$i/24" dev eth0
    ip -n "$name" link set eth0 up
    ip -n "$name" link set lo up
  done
  echo "hosts.sh: $count hosts up: $(host_names | tr '\n' ' ')"
}

run() {
  local host=$1; shift
  index_of "$host" >/dev/null
  # nsenter keeps /sys as it is (ip netns exec remounts it, which hides the
  # cgroup tree that slurmd needs); the UTS and mount namespaces give the
  # host its name and hosts file without touching the machine's.
  exec nsenter --net="/var/run/netns/$host" -- unshare --uts --mount -- \
    sh -c 'hostname "$0" && mount --bind "$1" /etc/hosts && shift && exec "$@"' \
    "$host" "$STATE/hosts" "$@"
}

check
case "${1:-}" in
  up) up "${2:-4}" ;;
  down) down ;;
  run) [ $# -ge 3 ] || die "usage: hosts.sh run HOST CMD..."; shift; run "$@" ;;
  cut) ip link set "${PREFIX}v$(index_of "$2")" down ;;
  heal) ip link set "${PREFIX}v$(index_of "$2")" up ;;
  kill) for pid in $(ip netns pids "$2"); do kill -9 "$pid" 2>/dev/null || true; done ;;
  address) echo "$SUBNET.$(index_of "$2")" ;;
  *) die "usage: hosts.sh up [N] | run HOST CMD... | cut HOST | heal HOST | kill HOST | address HOST | down" ;;
esac
