#!/usr/bin/env bash
# A run across hosts: tests/cluster/hosts.sh makes a learner host and three
# actor hosts (network namespaces on a bridge, each with its own address
# and hostname). With mutual TLS whose certificates name the hosts, the
# learner on vc-learner trains InvertedPendulum from one actor on each
# actor host, while
#   - an actor that dials the learner by an address its certificate does
#     not name is refused;
#   - vc-actor1's link is cut for 30 s mid-run: its registration stalls out
#     and the batch goes on without it; when the link is back it rejoins;
#   - every process of vc-actor2 is killed, and its actor started again;
# the run keeps updating throughout, finishes, reaches a mean return of
# 900 (a random policy gets 5-8) and keeps its checkpoints. Then two
# data-parallel learner replicas on vc-learner and vc-actor1, averaging
# their gradients over Gloo across the bridge, each serving the actor of
# another host, train it to 900 as well. Last, one host floods a learner
# with registrations it never uses (valid credentials, no stream): actors on
# the other hosts still register at once and train.
#
#   cluster_test.sh VANTAGE REGISTER_FLOOD
#     exit 0: passed, 77: namespaces unavailable
set -uo pipefail

readonly VANTAGE=$(realpath "$1")
readonly FLOOD=$(realpath "$2")
readonly HOSTS="$(dirname "$(realpath "$0")")/hosts.sh"
readonly WORK=$(mktemp -d /tmp/vantage-cluster.XXXXXX)
pids=()

cleanup() {
  for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null; done
  "$HOSTS" down >/dev/null 2>&1
  [ "${KEEP:-0}" = 1 ] || rm -rf "$WORK"
}
trap cleanup EXIT

fail() {
  echo "FAIL: $*"
  for log in "$WORK"/*.log; do echo "--- $log"; tail -n 15 "$log"; done
  exit 1
}

if ! "$HOSTS" up 4 >"$WORK/hosts.log" 2>&1; then
  if grep -q "hosts.sh:" "$WORK/hosts.log"; then
    echo "SKIP: $(cat "$WORK/hosts.log")"
    exit 77
  fi
  fail "hosts.sh up: $(cat "$WORK/hosts.log")"
fi

# A CA, a server certificate for vc-learner, one client certificate per
# actor host.
cd "$WORK"
certs() {
  openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=vantage-test-ca \
    -keyout ca.key -out ca.crt 2>/dev/null || return 1
  local name
  for name in vc-learner vc-actor1 vc-actor2 vc-actor3; do
    openssl req -newkey rsa:2048 -nodes -subj "/CN=$name" -keyout "$name.key" \
      -out "$name.csr" 2>/dev/null || return 1
    printf 'subjectAltName=DNS:%s\n' "$name" >"$name.ext"
    openssl x509 -req -in "$name.csr" -CA ca.crt -CAkey ca.key -CAcreateserial \
      -days 1 -extfile "$name.ext" -out "$name.crt" 2>/dev/null || return 1
  done
}
certs || fail "openssl could not make the certificates"

learner() {
  "$HOSTS" run vc-learner "$VANTAGE" learner --listen=0.0.0.0:50051 \
    --env=InvertedPendulum --envs=3 --horizon=1024 --algo=ppo \
    --estimator=maxabs --rho=0.4 --steps=1600000 --seed=1 \
    --actor_stall_timeout_s=10 --checkpoint_every=5 --keep_checkpoints=3 \
    --run_dir="$WORK/run" --tls_cert=vc-learner.crt --tls_key=vc-learner.key \
    --tls_ca=ca.crt >>"$WORK/learner.log" 2>&1
}
actor() {  # HOST [HOST:PORT]
  "$HOSTS" run "$1" "$VANTAGE" actor --learner="${2:-vc-learner:50051}" \
    --env=InvertedPendulum --envs=1 --name="$1" --tls_cert="$1.crt" \
    --tls_key="$1.key" --tls_ca=ca.crt "${@:3}" >>"$WORK/$1.log" 2>&1
}
updates() { [ -f run/progress.csv ] && echo $(($(wc -l <run/progress.csv) - 1)) || echo 0; }
wait_updates() {  # N SECONDS
  local i
  for i in $(seq 1 $((10 * $2))); do
    [ "$(updates)" -ge "$1" ] && return 0
    sleep 0.1
  done
  return 1
}

learner & pids+=($!)
for host in vc-actor1 vc-actor2 vc-actor3; do actor "$host" & pids+=($!); done

wait_updates 5 120 || fail "no 5 updates within 120 s"
# The learner's certificate names vc-learner, not its address: an actor that
# dials the address cannot verify it and is refused.
if actor vc-actor3 "$("$HOSTS" address vc-learner):50051" --max_reconnects=0; then
  fail "an actor that dialled the learner's bare address was let in"
fi
grep -q "giving up after 0 reconnects: registration: .*\(certificate\|handshake\|SSL\|ssl\|TLS\|tls\)" \
  vc-actor3.log || fail "the actor at the wrong name was not refused for its certificate"
echo "cluster: $(updates) updates before the faults"
"$HOSTS" cut vc-actor1
"$HOSTS" kill vc-actor2
cut_at=$(updates)
sleep 30
during=$(( $(updates) - cut_at ))
"$HOSTS" heal vc-actor1
actor vc-actor2 & pids+=($!)
echo "cluster: $during updates during the 30 s with vc-actor1 cut off and vc-actor2 killed"
[ "$during" -ge 2 ] || fail "the run stalled while two hosts were away ($during updates)"

# The cut actor's learner expired its registration; once its link is back
# it finds out and registers again, while the run goes on.
for _ in $(seq 1 600); do
  [ "$(grep -c "vc-actor1: registered as actor" vc-actor1.log)" -ge 2 ] && break
  kill -0 "${pids[0]}" 2>/dev/null || break
  sleep 0.1
done
echo "cluster: $(updates) updates when vc-actor1 was back"
wait "${pids[0]}"
status=$?
[ "$status" = 0 ] || fail "the learner exited with $status"
grep -q "owed .* steps and sent none" learner.log ||
  fail "the cut-off actor was never reported as stalled"
[ "$(grep -c "vc-actor1: registered as actor" vc-actor1.log)" -ge 2 ] ||
  fail "vc-actor1 did not register again after its link came back (before the run ended)"
best_return() {  # RUN_DIR
  python3 - "$1/progress.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print(max(float(r["mean_return"]) for r in rows if r["mean_return"]))
PY
}
at_least() { python3 -c "import sys; sys.exit(0 if float('$1') >= $2 else 1)"; }
best=$(best_return "$WORK/run")
echo "cluster: best mean return $best over $(updates) updates"
at_least "$best" 900 || fail "best mean return $best < 900"
ls run/checkpoints/checkpoint-*.pt >/dev/null 2>&1 || fail "no checkpoint kept"

replica() {  # HOST RANK
  "$HOSTS" run "$1" "$VANTAGE" learner --listen=0.0.0.0:50052 --rank="$2" \
    --learners=2 --rendezvous=vc-learner:29500 --env=InvertedPendulum \
    --envs=2 --horizon=1024 --algo=ppo --estimator=maxabs --rho=0.4 \
    --steps=300000 --seed=1 --run_dir="$WORK/replicas" \
    >>"$WORK/replica$2.log" 2>&1
}
replica vc-learner 0 & rank0=$!
replica vc-actor1 1 & rank1=$!
pids+=("$rank0" "$rank1")
for pair in vc-actor2:vc-learner vc-actor3:vc-actor1; do
  "$HOSTS" run "${pair%%:*}" "$VANTAGE" actor --learner="${pair#*:}:50052" \
    --env=InvertedPendulum --envs=1 >>"$WORK/${pair%%:*}.dp.log" 2>&1 &
  pids+=($!)
done
wait "$rank0" || fail "learner replica 0 failed"
wait "$rank1" || fail "learner replica 1 failed"
grep -q "replica 1 of 2 joined at vc-learner:29500" replica1.log ||
  fail "replica 1 did not join replica 0 across the bridge"
best=$(best_return "$WORK/replicas")
echo "cluster: two replicas on two hosts, best mean return $best"
at_least "$best" 900 || fail "two replicas: best mean return $best < 900"

"$HOSTS" run vc-learner "$VANTAGE" learner --listen=0.0.0.0:50053 \
  --env=InvertedPendulum --envs=2 --horizon=256 --steps=20480 --seed=2 \
  --run_dir="$WORK/flooded" --tls_cert=vc-learner.crt --tls_key=vc-learner.key \
  --tls_ca=ca.crt >>"$WORK/flooded.log" 2>&1 &
flooded=$!
pids+=("$flooded")
for _ in $(seq 1 200); do
  grep -q "serving on port" flooded.log && break
  sleep 0.05
done
"$HOSTS" run vc-actor3 "$FLOOD" vc-learner:50053 12 InvertedPendulum \
  vc-actor3.crt vc-actor3.key ca.crt >"$WORK/flood.out" 2>&1 &
flood=$!
pids+=("$flood")
sleep 3  # the flood is on
registrations() { grep -c "registered as actor" "$1.log"; }
declare -A before
for host in vc-actor1 vc-actor2; do before[$host]=$(registrations "$host"); done
started=$(date +%s%N)
for host in vc-actor1 vc-actor2; do
  actor "$host" vc-learner:50053 &
  pids+=($!)
done
for host in vc-actor1 vc-actor2; do
  for _ in $(seq 1 100); do
    [ "$(registrations "$host")" -gt "${before[$host]}" ] && break
    sleep 0.05
  done
done
took=$(( ($(date +%s%N) - started) / 1000000 ))
wait "$flood"
cat flood.out
echo "cluster: during the flood, the other hosts' actors registered within ${took} ms"
[ "$took" -le 5000 ] || fail "actors waited ${took} ms to register during a flood"
grep -q "register_flood: code 8" flood.out ||
  fail "the flooding host was never refused (RESOURCE_EXHAUSTED)"
wait "$flooded" || fail "the flooded learner did not finish"
echo "PASS"
