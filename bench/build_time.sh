#!/usr/bin/env bash
# Measures a cold build of a clean clone against a reference compile made in
# the same run, so that figures from different machines can be compared as
# ratios. HEAD's tree (commit first) is configured in a temporary
# directory and built with ccache off; the reference is one translation unit
# that includes <torch/torch.h> and <grpcpp/grpcpp.h>, compiled with the
# flags of the project's own LibTorch sources, twice before and twice after
# the build (the median counts), without the precompiled header.
# Prints the wall time, the serial CPU time (the sum of every edge's time in
# .ninja_log), that sum in reference compiles, and the slowest edges.
# Usage: bench/build_time.sh [--target T (vantage)] [--jobs N (nproc)]
#          [--tests] [--touch FILE]... [--keep DIR] [-- CMAKE_ARGS...]
#   --tests     configure as `deploy/setup.sh --tests` does (tests,
#               benchmarks) instead of as the first command does
#   --touch F   after the build, touch F (a path in the repository) and
#               report how many translation units the full build then
#               recompiles, and how long that takes (ccache off)
#   --keep DIR  build in DIR (kept) instead of a temporary directory
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
target=vantage
jobs="$(nproc)"
with_tests=0
keep=""
touches=()
cmake_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --target) target="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --tests) with_tests=1; shift ;;
    --touch) touches+=("$2"); shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    --) shift; cmake_args+=("$@"); break ;;
    -h|--help) sed -n '2,17p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "build_time.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
for f in "${touches[@]}"; do
  [[ -f "${repo_root}/${f}" ]] || { echo "build_time.sh: --touch ${f}: no such file in the repository" >&2; exit 2; }
done

if [[ -n "${keep}" ]]; then
  [[ ! -e "${keep}" ]] || { echo "build_time.sh: --keep ${keep} exists" >&2; exit 2; }
  work="${keep}"
  mkdir -p "${work}"
else
  work="$(mktemp -d)"
  trap 'rm -rf "${work}"' EXIT
fi
export CCACHE_DISABLE=1
# HEAD's files alone, as a clean checkout has them.
mkdir -p "${work}/src"
git -C "${repo_root}" archive HEAD | tar -x -C "${work}/src"
if [[ "${with_tests}" -eq 1 ]]; then
  cmake_args=(-DVANTAGE_BUILD_TESTS=ON -DVANTAGE_BUILD_BENCHMARKS=ON "${cmake_args[@]}")
else
  cmake_args=(-DVANTAGE_BUILD_TESTS=OFF -DVANTAGE_BUILD_BENCHMARKS=OFF "${cmake_args[@]}")
fi
# The compiler deploy/setup.sh gives a new tree, unless CXX names another.
cmake -S "${work}/src" -B "${work}/src/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER="${CXX:-clang++-14}" "${cmake_args[@]}" >"${work}/configure.log"

# The reference compile uses the command line of a LibTorch source of the
# project (compile_commands.json), with its source swapped for the reference.
printf '#include <torch/torch.h>\n#include <grpcpp/grpcpp.h>\nint main() { return 0; }\n' \
  >"${work}/reference.cc"
reference_command() {
  python3 - "${work}/src/build/compile_commands.json" "${work}/reference.cc" "${work}/reference.o" <<'EOF'
import json, shlex, sys
entries = json.load(open(sys.argv[1]))
entry = next(e for e in entries if e["file"].endswith("common/nn/networks.cc"))
words = shlex.split(entry["command"])
# Drop a launcher (env ... ccache) before the compiler.
while words and not words[0].endswith(("g++", "c++", "clang++", "clang++-14")):
    words.pop(0)
# Drop the outputs, and the precompiled header: the reference parses the
# headers itself (g++ would pick the header's .gch up from `-include`
# once the build has made it; clang names it with -Xclang -include-pch).
out = []
i = 0
while i < len(words):
    w = words[i]
    if w == "-Xclang" and i + 1 < len(words) and words[i + 1] in ("-include-pch", "-include"):
        i += 4
    elif w == "-include" and "cmake_pch" in words[i + 1]:
        i += 2
    elif w in ("-o", "-MF", "-MT", "-c"):
        i += 2
    elif w in ("-MD", "-MMD", "-Winvalid-pch"):
        i += 1
    else:
        out.append(w)
        i += 1
print(shlex.join(out + ["-c", sys.argv[2], "-o", sys.argv[3]]))
EOF
}
ref_cmd="$(reference_command)"
time_reference() {
  local start end
  start=$(date +%s.%N)
  (cd "${work}/src/build" && eval "${ref_cmd}")
  end=$(date +%s.%N)
  python3 -c "print(f'{${end} - ${start}:.1f}')"
}
ref_before="$(time_reference)"
ref_before2="$(time_reference)"

start=$(date +%s)
cmake --build "${work}/src/build" --target "${target}" -j "${jobs}" >"${work}/build.log"
end=$(date +%s)
ref_after="$(time_reference)"
ref_after2="$(time_reference)"

ninja_summary() {
  python3 - "$1" "$2" "$3" <<'EOF'
import sys
log, ref, top = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
edges = {}
for line in open(log):
    if line.startswith("#"):
        continue
    start, end, _, output, _ = line.rstrip("\n").split("\t")
    edges[output] = (int(end) - int(start)) / 1000.0
total = sum(edges.values())
compiles = [o for o in edges if o.endswith(".o")]
print(f"edges: {len(edges)} ({len(compiles)} compiles)")
print(f"serial CPU time: {total / 60:.1f} min = {total / ref:.1f} reference compiles")
for output, seconds in sorted(edges.items(), key=lambda e: -e[1])[:top]:
    print(f"  {seconds:6.1f} s  {output}")
EOF
}
ref_mean="$(python3 -c "import statistics; print(f'{statistics.median([${ref_before}, ${ref_before2}, ${ref_after}, ${ref_after2}]):.1f}')")"
echo "build_time.sh: target ${target}, ${jobs} jobs, $(git -C "${repo_root}" rev-parse --short HEAD), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs))"
echo "reference compile (<torch/torch.h> + <grpcpp/grpcpp.h>): ${ref_before} and ${ref_before2} s before, ${ref_after} and ${ref_after2} s after, median ${ref_mean} s"
echo "wall time: $(( (end - start) / 60 )) min $(( (end - start) % 60 )) s"
ninja_summary "${work}/src/build/.ninja_log" "${ref_mean}" 12

# The touches are measured against a complete build.
[[ ${#touches[@]} -eq 0 ]] || cmake --build "${work}/src/build" -j "${jobs}" >>"${work}/build.log"
for f in "${touches[@]}"; do
  total_tus="$(ninja -C "${work}/src/build" -t commands | grep -c ' -c ' || true)"
  touch "${work}/src/${f}"
  start=$(date +%s)
  cmake --build "${work}/src/build" -j "${jobs}" >"${work}/touch.log"
  end=$(date +%s)
  # ninja -n cannot tell: the glob check of the format target re-runs CMake.
  again="$(grep -c 'Building CXX' "${work}/touch.log" || true)"
  echo "touch ${f}: ${again} of ${total_tus} translation units recompile (full build), $(( end - start )) s"
done
