#!/usr/bin/env bash
# Installs vantage's build dependencies from Debian packages (only the ones
# missing), then configures and builds the project into ./build with Ninja.
# Usage: deploy/setup.sh [--build-dir DIR] [--build-type Release|Debug|...]
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${repo_root}/build"
build_type="Release"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    --build-type) build_type="$2"; shift 2 ;;
    -h|--help) sed -n '2,4p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "setup.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

# The mujoco CMake config calls find_dependency(OpenGL) and needs Qhull's
# config, hence libgl-dev, libopengl-dev and libqhull-dev. libgloo-dev holds
# the headers of the Gloo engine that LibTorch's c10d runs data-parallel
# learners on. libopenblas0-serial takes libblas.so.3 (Debian's
# alternatives) over from the reference BLAS that LibTorch's GEMMs would
# otherwise run on; serial, because every vantage process computes on one
# thread of its own and several share the machine (docs/benchmarks.md).
# prometheus (with promtool) serves deploy/prometheus/ and its test;
# python3-matplotlib draws `vantage plot`'s figures and python3-scipy computes
# the statistics of `vantage experiment report`. `vantage rollout
# --video` renders MuJoCo offscreen on OSMesa (libosmesa6-dev), draws the
# Bullet characters with Cairo (libcairo2-dev) and encodes with FFmpeg's
# libraries (libav*-dev, libswscale-dev); its tests read the files back
# with ffprobe and ffmpeg (ffmpeg). ccache keeps compiled objects for the
# next build of any clone, the fuzz build and the container image's
# (CMakeLists.txt).
packages=(
  build-essential cmake ninja-build ccache pkgconf clang-format openssl
  libtorch-dev libgloo-dev libopenblas0-serial
  libmujoco-dev libqhull-dev libgl-dev libopengl-dev
  libbullet-dev
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libabsl-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  prometheus-cpp-dev
  libminizip-dev
  prometheus python3-matplotlib python3-scipy
  libosmesa6-dev libcairo2-dev
  libavcodec-dev libavformat-dev libswscale-dev libavutil-dev ffmpeg
)

# Only the tests of deploy/ need these (kept apart from packages=(...),
# which the container image's build stage installs): Slurm's daemons
# (slurm-wlm, munge) for tests/deploy/slurm/; buildah and debootstrap to
# build the image here (tests/deploy/docker/); python3-yaml to read the
# rendered Kubernetes manifests (tests/deploy/k8s/), kubectl to render them
# and Node.js with npm to validate them. A machine that has kubectl or
# npm from elsewhere keeps them (Debian's packages would conflict).
test_packages=(slurm-wlm munge buildah debootstrap python3-yaml)
command -v kubectl >/dev/null || test_packages+=(kubernetes-client)
command -v npm >/dev/null || test_packages+=(nodejs npm)

"${repo_root}/deploy/install_packages.sh" setup.sh "${packages[@]}" \
  "${test_packages[@]}"

cmake -S "${repo_root}" -B "${build_dir}" -G Ninja -DCMAKE_BUILD_TYPE="${build_type}"
cmake --build "${build_dir}"
