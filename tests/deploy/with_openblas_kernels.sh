#!/usr/bin/env bash
# Runs a command under one of OpenBLAS's kernel sets (OPENBLAS_CORETYPE),
# or exits 77 (skipped) when this CPU cannot run that set's instructions.
# Learning curves move with the kernels, so the learning tests run under a
# second set besides the machine's own.
# Usage: with_openblas_kernels.sh Haswell|SkylakeX|Zen COMMAND [ARGS...]
set -euo pipefail
kernels="${1:?usage: with_openblas_kernels.sh KERNELS COMMAND [ARGS...]}"
shift
case "${kernels}" in
  SkylakeX) needs=avx512f ;;
  Haswell|Zen) needs=avx2 ;;
  *) echo "with_openblas_kernels.sh: unknown kernel set '${kernels}'" >&2; exit 2 ;;
esac
if ! grep -qw "${needs}" /proc/cpuinfo; then
  echo "this CPU has no ${needs}: the ${kernels} kernels cannot run here"
  exit 77
fi
OPENBLAS_CORETYPE="${kernels}" exec "$@"
