#!/usr/bin/env bash
# Rewrites every report.md (and its figures) under bench/results from the
# committed cells, with the binary given (default build/vantage); the order
# grid also gets its pre-registered tests of min and max against the 2nd
# and 3rd order statistics at the same rho, and the sparse grids their
# tests against plain TRPO. Usage: bench/results/regenerate.sh [VANTAGE]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
vantage=${1:-$here/../../build/vantage}
for experiment in "$here"/*/experiment.json; do
  dir=$(dirname "$experiment")
  "$vantage" experiment report "$dir"
done
for order in 2 3; do
  "$vantage" experiment report "$here/order_rho" --baseline=order:$order \
    --match=rho --groups='order1-*,order4-*' --no_figures \
    --out="$here/order_rho/report_vs_order$order.md"
done
# The sparse grids also test EX2 alone and max and min over EX2 against
# plain TRPO (their `gae` group run without exploration).
for experiment in $(grep -lE '"exploration": *"none"' "$here"/*/experiment.json); do
  dir=$(dirname "$experiment")
  "$vantage" experiment report "$dir" --baseline_set=exploration=none \
    --no_figures --out="$dir/report_vs_trpo.md"
done
# The maze with EX2's code's inputs pre-registers each of its tests as a
# family of one (docs/experiments.md): EX2 alone against plain TRPO, and
# max over EX2 against EX2 alone.
rllab=$here/sparse_maze_rllab
"$vantage" experiment report "$rllab" --baseline_set=exploration=none \
  --groups=gae --no_figures --out="$rllab/report_vs_trpo.md"
if compgen -G "$rllab/TwoDMaze/max-*" > /dev/null; then
  "$vantage" experiment report "$rllab" --groups='max-*' --no_figures \
    --out="$rllab/report_max.md"
fi
