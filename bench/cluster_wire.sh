#!/usr/bin/env bash
# The wire between an actor host and a learner host, measured on two
# namespace hosts (tests/cluster/hosts.sh): bytes on the actor's link per
# environment step (everything the link carries: segments, weights, gRPC,
# TCP), then the actor's env steps/s with the link's egress limited by a
# token bucket (tc tbf) at decreasing rates, to find the rate below which
# it slows down. Ratios against the unlimited link of the same run.
#
#   bench/cluster_wire.sh VANTAGE [ENV] [ENVS] [RATES...]
#     defaults: HalfCheetah, 8 envs, 100mbit 30mbit 10mbit 3mbit 1mbit
# Needs root and network namespaces (exit 2 otherwise).
set -uo pipefail

readonly VANTAGE=$(realpath "$1")
readonly ENV=${2:-HalfCheetah}
readonly ENVS=${3:-8}
shift 3 2>/dev/null || shift $#
RATES=("$@")
[ ${#RATES[@]} -gt 0 ] || RATES=(100mbit 30mbit 10mbit 3mbit 1mbit)
readonly HOSTS="$(dirname "$(realpath "$0")")/../tests/cluster/hosts.sh"
readonly WORK=$(mktemp -d /tmp/vantage-wire.XXXXXX)
readonly WINDOW=${WINDOW:-12}
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null; done
  "$HOSTS" down >/dev/null 2>&1
  rm -rf "$WORK"
}
trap cleanup EXIT
"$HOSTS" up 2 >/dev/null || exit 2

# Asynchronous (lag 4), so that the actor acts while the learner updates:
# its rate is its own and the link's, not the update's.
"$HOSTS" run vc-learner "$VANTAGE" learner --listen=0.0.0.0:50051 --env="$ENV" \
  --envs="$ENVS" --nosync --max_policy_lag=4 --steps=1000000000 --seed=1 \
  --run_dir="$WORK/run" >"$WORK/learner.log" 2>&1 &
pids+=($!)
"$HOSTS" run vc-actor1 "$VANTAGE" actor --learner=vc-learner:50051 --env="$ENV" \
  --envs="$ENVS" >"$WORK/actor.log" 2>&1 &
pids+=($!)

steps() { awk -F, 'NR > 1 {last = $1} END {print last}' "$WORK/run/progress.csv" 2>/dev/null; }
tx_bytes() { cat /sys/class/net/vcv2/statistics/rx_bytes; }  # from vc-actor1
rx_bytes() { cat /sys/class/net/vcv2/statistics/tx_bytes; }  # to vc-actor1
for _ in $(seq 1 300); do [ -n "$(steps)" ] && break; sleep 0.1; done
[ -n "$(steps)" ] || { echo "no update; logs:"; tail "$WORK"/*.log; exit 1; }
sleep 3

measure() {  # prints "steps/s up_bytes/step down_bytes/step"
  local s0 u0 d0 s1 u1 d1
  s0=$(steps); u0=$(tx_bytes); d0=$(rx_bytes)
  sleep "$WINDOW"
  s1=$(steps); u1=$(tx_bytes); d1=$(rx_bytes)
  python3 -c "s=$s1-$s0; print(f'{s/$WINDOW:.0f} {($u1-$u0)/max(s,1):.0f} {($d1-$d0)/max(s,1):.0f}')"
}

read -r base up down <<<"$(measure)"
[ -n "${base:-}" ] && [ "$base" != 0 ] || {
  echo "no progress within ${WINDOW}s (the learner may be the bottleneck); logs:"
  tail -n 5 "$WORK"/*.log
  exit 1
}
echo "wire: $ENV, one actor of $ENVS envs on its own host, asynchronous learner"
echo "  unlimited link: $base env steps/s; per env step $up bytes actor->learner," \
  "$down bytes learner->actor"
for rate in "${RATES[@]}"; do
  "$HOSTS" run vc-actor1 tc qdisc replace dev eth0 root tbf rate "$rate" \
    burst 64kb latency 400ms
  sleep 2
  read -r limited _ _ <<<"$(measure)"
  python3 -c "print(f'  egress {\"$rate\":>8s}: {$limited:7d} env steps/s, {$limited/$base:.2f}x unlimited')"
done
"$HOSTS" run vc-actor1 tc qdisc del dev eth0 root 2>/dev/null
echo "RESULT wire env=$ENV envs=$ENVS steps_per_s=$base up_bytes_per_step=$up down_bytes_per_step=$down"
