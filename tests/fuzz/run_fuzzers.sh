#!/usr/bin/env bash
# Builds the libFuzzer fuzzers (ASan + UBSan, clang-14) and runs each on a
# copy of its seed corpus for a bounded time; fails on any crash, leak,
# timeout or sanitizer report.
# Usage: tests/fuzz/run_fuzzers.sh [--seconds N] [--build-dir DIR] [--jobs J]
#   J: parallel compile jobs and fuzzers running at once (default 2)
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
fuzz_dir="${repo_root}/tests/fuzz"
build_dir="${repo_root}/build-fuzz"
seconds=60
jobs=2
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --build-dir) build_dir="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    -h|--help) sed -n '2,6p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "run_fuzzers.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if ! [[ "${seconds}" =~ ^[1-9][0-9]*$ ]]; then
  echo "run_fuzzers.sh: --seconds needs a whole number >= 1, got '${seconds}'" >&2
  exit 2
fi
if ! [[ "${jobs}" =~ ^[1-9][0-9]*$ ]]; then
  echo "run_fuzzers.sh: --jobs needs a whole number >= 1, got '${jobs}'" >&2
  exit 2
fi

# The rest of the toolchain comes from deploy/setup.sh; this adds clang and
# its sanitizer and libFuzzer runtimes.
packages=(clang-14 libclang-rt-14-dev)
"${repo_root}/deploy/install_packages.sh" run_fuzzers.sh "${packages[@]}"

cmake -S "${repo_root}" -B "${build_dir}" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER=clang++-14 -DVANTAGE_BUILD_FUZZERS=ON \
  -DVANTAGE_BUILD_TESTS=OFF -DVANTAGE_BUILD_BENCHMARKS=OFF
cmake --build "${build_dir}" --target fuzzers -j "${jobs}"

# Every report is fatal (UBSan's already is: -fno-sanitize-recover), and
# leaks are reported except the third-party ones lsan.supp explains.
asan_options="halt_on_error=1:abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="halt_on_error=1:abort_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=${fuzz_dir}/lsan.supp:print_suppressions=0"
# checkpoint: its lsan.supp entry names a LibTorch frame, which only the
# slow unwinder reaches (LibTorch has no frame pointers); slower, so only
# for this fuzzer.
declare -A extra_asan_options=(
  [checkpoint]=":fast_unwind_on_malloc=0:malloc_context_size=16"
)

runs_dir="${build_dir}/fuzz-runs"
rm -rf "${runs_dir}"
mkdir -p "${runs_dir}"

# Runs one fuzzer for the time given; its verdict is the exit status, its
# output the log in its work directory.
run_one() {
  local name="$1" work="$2"
  local binary="${build_dir}/fuzz/${name}_fuzzer"
  # A copy: libFuzzer adds what it finds to the corpus it is given.
  mkdir "${work}/corpus"
  cp -R "${fuzz_dir}/corpus/${name}/." "${work}/corpus/" || return 1
  # A dictionary of the input's tokens, if the fuzzer has one.
  local dict=()
  if [[ -f "${fuzz_dir}/${name}.dict" ]]; then
    dict=(-dict="${fuzz_dir}/${name}.dict")
  fi
  cd "${work}" && ASAN_OPTIONS="${asan_options}${extra_asan_options[${name}]:-}" \
    "${binary}" -max_total_time="${seconds}" \
    -rss_limit_mb=4096 -timeout=25 -print_final_stats=1 \
    -artifact_prefix="${work}/" "${dict[@]}" corpus >"${work}/log.txt" 2>&1
}

# Up to --jobs fuzzers at once (each is one process on one core); the
# verdicts are read in a fixed order once all have ended.
names=()
summary=()
passed=0
failed=0
for source in "${fuzz_dir}"/*_fuzzer.cc; do
  name="$(basename "${source}" _fuzzer.cc)"
  if [[ ! -d "${fuzz_dir}/corpus/${name}" ]]; then
    echo "run_fuzzers.sh: ${name} has no seed corpus tests/fuzz/corpus/${name}" >&2
    summary+=("fuzz ${name}: 0 runs, FAILED (no seed corpus)")
    failed=$((failed + 1))
    continue
  fi
  while [[ "$(jobs -rp | wc -l)" -ge "${jobs}" ]]; do wait -n || true; done
  mkdir -p "${runs_dir}/${name}"
  echo "run_fuzzers.sh: ${name} for ${seconds} s (log ${runs_dir}/${name}/log.txt)"
  {
    status=0
    run_one "${name}" "${runs_dir}/${name}" || status=$?
    echo "${status}" >"${runs_dir}/${name}/status"
  } &
  names+=("${name}")
done

wait
for name in "${names[@]}"; do
  work="${runs_dir}/${name}"
  log="${work}/log.txt"
  binary="${build_dir}/fuzz/${name}_fuzzer"
  status="$(cat "${work}/status" 2>/dev/null || echo "no status")"
  runs="$(sed -n 's/^stat::number_of_executed_units: *\([0-9]*\).*/\1/p' "${log}" | tail -n 1)"
  runs="${runs:-0}"
  reproducer="$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "${log}" | tail -n 1)"
  report="$(grep -m 1 -E 'ERROR: (Address|Leak|Undefined)Sanitizer|runtime error:|ERROR: libFuzzer|fuzz invariant broken' "${log}" || true)"
  if [[ "${status}" == 0 && -z "${reproducer}" && -z "${report}" ]]; then
    summary+=("fuzz ${name}: ${runs} runs, ok")
    passed=$((passed + 1))
  else
    echo "run_fuzzers.sh: ${name} FAILED (exit ${status}): ${report:-see the log}" >&2
    echo "run_fuzzers.sh: reproducer: ${reproducer:-none written}; log: ${log}" >&2
    echo "run_fuzzers.sh: rerun with ASAN_OPTIONS=${asan_options}${extra_asan_options[${name}]:-}" \
      "LSAN_OPTIONS=${LSAN_OPTIONS} UBSAN_OPTIONS=${UBSAN_OPTIONS}" \
      "${binary} ${reproducer:-<input>}" >&2
    tail -n 40 "${log}" >&2
    summary+=("fuzz ${name}: ${runs} runs, FAILED (reproducer: ${reproducer:-none}, log: ${log})")
    failed=$((failed + 1))
  fi
done

printf '%s\n' "${summary[@]}"
echo "${passed} passed, ${failed} failed"
[[ ${failed} -eq 0 ]]
