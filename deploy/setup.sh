#!/usr/bin/env bash
# Installs vantage's build dependencies from Debian packages (only the ones
# missing), then configures and builds into ./build with Ninja: the
# `vantage` binary alone, or with --tests everything (the test suite, the
# benchmarks of `vantage bench`) after the packages only the tests need.
# Usage: deploy/setup.sh [--tests] [--packages-only] [--build-dir DIR]
#          [--build-type Release|Debug|...]
#   --tests          also the tests' packages, tests and benchmarks
#   --packages-only  install the packages and stop (the container image's
#                    build stage); without --tests, the binary's only
# A build directory configured with the tests keeps them when setup.sh runs
# again without --tests (only the binary is rebuilt then).
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${repo_root}/build"
build_type="Release"
with_tests=0
packages_only=0
need_value() {
  [[ $# -ge 2 && -n "$2" ]] || { echo "setup.sh: $1 needs a value (see --help)" >&2; exit 2; }
}
while [[ $# -gt 0 ]]; do
  case "$1" in
    --tests) with_tests=1; shift ;;
    --packages-only) packages_only=1; shift ;;
    --build-dir) need_value "$@"; build_dir="$2"; shift 2 ;;
    --build-type) need_value "$@"; build_type="$2"; shift 2 ;;
    -h|--help) sed -n '2,12p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "setup.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

# The mujoco CMake config calls find_dependency(OpenGL) and needs Qhull's
# config, hence libgl-dev, libopengl-dev and libqhull-dev. libgloo-dev holds
# the headers of the Gloo engine that LibTorch's c10d runs data-parallel
# learners on. libopenblas0-serial takes libblas.so.3 (Debian's
# alternatives) over from the reference BLAS that LibTorch's GEMMs would
# otherwise run on; serial, because every vantage process computes on one
# thread of its own and several share the machine. Not the pthread build:
# its 60 KB of thread-local storage leaves no room in civetweb's 100 KB
# thread stacks once LibTorch is loaded, so no metrics endpoint starts.
# The serial build must not be called from two threads at once (Debian
# builds it without locks), which no vantage process does
# (docs/benchmarks.md).
# libblas-dev: the C interface (cblas.h) the actors' MLP policies call
# BLAS through, linked as libblas.so.3 and so run on OpenBLAS too.
# prometheus (with promtool) serves deploy/prometheus/watch_runs.sh;
# python3-matplotlib draws `vantage plot`'s figures and python3-scipy computes
# the statistics of `vantage experiment report`. Actors embed CPython for
# Python environments (python3-dev, pybind11-dev, python3-numpy). `vantage rollout
# --video` renders MuJoCo offscreen on OSMesa (libosmesa6-dev), draws the
# Bullet characters with Cairo (libcairo2-dev) and encodes with FFmpeg's
# libraries (libav*-dev, libswscale-dev). libbenchmark-dev: the container
# image's build stage, which installs this list, builds `vantage bench`.
# `vantage export` writes ONNX models with libonnx-dev (ONNX's protobuf
# messages and its checker).
# ccache keeps compiled objects for the next build of any clone, the fuzz
# build and the container image's (CMakeLists.txt). clang-14 compiles: it
# parses LibTorch's headers faster than g++ and loads them precompiled in a
# fraction of g++'s time (docs/development.md#build-times); build-essential
# still brings the C++ library and the linker.
packages=(
  build-essential clang-14 cmake ninja-build ccache pkgconf openssl
  libtorch-dev libgloo-dev libopenblas0-serial libblas-dev
  libmujoco-dev libqhull-dev libgl-dev libopengl-dev
  libbullet-dev
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libabsl-dev
  libbenchmark-dev
  prometheus-cpp-dev
  libminizip-dev
  prometheus python3-matplotlib python3-scipy
  python3-dev pybind11-dev python3-numpy
  libosmesa6-dev libcairo2-dev
  libavcodec-dev libavformat-dev libswscale-dev libavutil-dev
  libonnx-dev
)

# Only the tests need these (kept apart from packages=(...), which the
# container image's build stage installs): GoogleTest and clang-format (the
# format check); ffprobe and ffmpeg (ffmpeg) read the videos of `vantage
# rollout --video` back; Slurm's daemons (slurm-wlm, munge) for
# tests/deploy/slurm/; buildah and debootstrap to build the image here
# (tests/deploy/docker/); python3-yaml to read the rendered Kubernetes
# manifests (tests/deploy/k8s/), kubectl to render them and Node.js with npm
# to validate them. A machine that has kubectl or npm from elsewhere keeps
# them (Debian's packages would conflict). OpenCV's DNN module
# (libopencv-dnn-dev) runs exported ONNX policies as an independent runtime.
test_packages=(libgtest-dev libgmock-dev clang-format ffmpeg
  slurm-wlm munge buildah debootstrap python3-yaml iproute2 util-linux
  libopencv-dnn-dev)
command -v kubectl >/dev/null || test_packages+=(kubernetes-client)
command -v npm >/dev/null || test_packages+=(nodejs npm)

wanted=("${packages[@]}")
[[ "${with_tests}" -eq 1 ]] && wanted+=("${test_packages[@]}")
"${repo_root}/deploy/install_packages.sh" setup.sh "${wanted[@]}"
# A machine that also has OpenBLAS's pthread build gets it by Debian's
# priorities (100 against the serial build's 90); vantage needs the serial
# one (above), so it is selected by name.
serial_blas=/usr/lib/x86_64-linux-gnu/openblas-serial
if [[ -e /usr/lib/x86_64-linux-gnu/openblas-pthread/libopenblas.so.0 ]]; then
  as_root=()
  [[ "$(id -u)" -eq 0 ]] || as_root=(sudo)
  for link in libblas.so.3 liblapack.so.3 libopenblas.so.0; do
    "${as_root[@]}" update-alternatives --quiet \
      --set "${link}-x86_64-linux-gnu" "${serial_blas}/${link}"
  done
fi
[[ "${packages_only}" -eq 1 ]] && exit 0

configure=(-G Ninja -DCMAKE_BUILD_TYPE="${build_type}")
# A build tree keeps the compiler it was configured with (CMake would
# discard the tree's settings to change it); a new one gets clang, or the
# compiler named by CXX.
if [[ ! -f "${build_dir}/CMakeCache.txt" ]]; then
  configure+=(-DCMAKE_CXX_COMPILER="${CXX:-clang++-14}")
fi
if [[ "${with_tests}" -eq 1 ]]; then
  configure+=(-DVANTAGE_BUILD_TESTS=ON -DVANTAGE_BUILD_BENCHMARKS=ON)
elif [[ ! -f "${build_dir}/CMakeCache.txt" ]]; then
  configure+=(-DVANTAGE_BUILD_TESTS=OFF -DVANTAGE_BUILD_BENCHMARKS=OFF)
fi
cmake -S "${repo_root}" -B "${build_dir}" "${configure[@]}"
if [[ "${with_tests}" -eq 1 ]]; then
  cmake --build "${build_dir}"
else
  cmake --build "${build_dir}" --target vantage
fi
