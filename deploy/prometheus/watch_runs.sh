#!/usr/bin/env bash
# Runs Prometheus (Debian's, from deploy/setup.sh) over every vantage run
# under RUNS_DIR, at any depth (an experiment's EXP/<env>/<cell>/seed-<s>
# included): a copy of prometheus.yml and alerts.yml goes to STATE_DIR, and
# every 5 s each run's prometheus_targets.json is linked into
# STATE_DIR/targets/ (Prometheus reads target files from one directory
# only), links to runs that are gone removed. Stops Prometheus on
# SIGINT/SIGTERM.
# Usage: deploy/prometheus/watch_runs.sh RUNS_DIR [--listen HOST:PORT]
#          [--state DIR (RUNS_DIR/.prometheus)] [--retention DURATION (30d)]
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
usage() { sed -n '2,10p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
[[ $# -ge 1 ]] || { usage >&2; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac
runs="$1"
shift
listen="127.0.0.1:9090"
state=""
retention="30d"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --listen) listen="$2"; shift 2 ;;
    --state) state="$2"; shift 2 ;;
    --retention) retention="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "watch_runs.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ -d "${runs}" ]] || { echo "watch_runs.sh: no such directory: ${runs}" >&2; exit 2; }
command -v prometheus >/dev/null || {
  echo "watch_runs.sh: prometheus is not installed (deploy/setup.sh installs it)" >&2
  exit 1
}
runs="$(cd "${runs}" && pwd)"
state="${state:-${runs}/.prometheus}"
mkdir -p "${state}/targets" "${state}/data"
state="$(cd "${state}" && pwd)"
cp "${here}/prometheus.yml" "${here}/alerts.yml" "${state}/"

# One link per run, named after the run's path below RUNS_DIR.
sync_targets() {
  local file name
  while IFS= read -r -d '' file; do
    name="${file#"${runs}"/}"
    name="${name%/prometheus_targets.json}"
    name="${name//\//__}.json"
    [[ "$(readlink "${state}/targets/${name}" 2>/dev/null)" == "${file}" ]] ||
      ln -sfn "${file}" "${state}/targets/${name}"
  done < <(find "${runs}" -path "${state}" -prune -o \
             -name prometheus_targets.json -type f -print0 2>/dev/null)
  find "${state}/targets" -xtype l -delete 2>/dev/null || true
}

sync_targets
prometheus --config.file="${state}/prometheus.yml" \
  --storage.tsdb.path="${state}/data" \
  --storage.tsdb.retention.time="${retention}" \
  --web.listen-address="${listen}" >"${state}/prometheus.log" 2>&1 &
prometheus_pid=$!
stop() {
  kill -TERM "${prometheus_pid}" 2>/dev/null || true
  wait "${prometheus_pid}" 2>/dev/null || true
  exit 0
}
trap stop INT TERM
echo "watch_runs.sh: Prometheus on http://${listen} over the runs in ${runs} (log: ${state}/prometheus.log)"
while kill -0 "${prometheus_pid}" 2>/dev/null; do
  sync_targets
  sleep 5 &
  wait $! || true
done
status=0
wait "${prometheus_pid}" || status=$?
echo "watch_runs.sh: prometheus ended (exit ${status}); see ${state}/prometheus.log" >&2
exit "${status}"
