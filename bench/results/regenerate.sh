#!/usr/bin/env bash
# Rewrites every report.md (and its figures) under bench/results from the
# committed cells, with the binary given (default build/vantage); the order
# grid also gets its pre-registered tests against the 2nd and 3rd order
# statistics at the same rho. Usage: bench/results/regenerate.sh [VANTAGE]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
vantage=${1:-$here/../../build/vantage}
for experiment in "$here"/*/experiment.json; do
  dir=$(dirname "$experiment")
  "$vantage" experiment report "$dir"
done
for order in 2 3; do
  "$vantage" experiment report "$here/order_rho" --baseline=order:$order \
    --match=rho --no_figures --out="$here/order_rho/report_vs_order$order.md"
done
