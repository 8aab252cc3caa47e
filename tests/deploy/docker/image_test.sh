#!/usr/bin/env bash
# End-to-end test of the container image: builds it with
# deploy/docker/build_image.sh (buildah on a debootstrapped base), then runs
# its binary in a buildah container with chroot isolation (this sandbox
# refuses podman's OCI runtime; `buildah run` honours the image's USER and
# WORKDIR but not its ENTRYPOINT, so commands name `vantage`). Checks: the
# image's entrypoint, command, user and working directory; `envs`; a short
# local `train` into a run directory written by the non-root user; MuJoCo
# and Bullet rollouts with videos; `plot` failing clearly without Python;
# OpenBLAS as the BLAS; no -dev package, compiler, Python or source tree in
# the image; its size under a bound. Any failure ends the test with one
# FAIL line (exit 1); the containers it made are removed however it ends.
# Needs root and buildah, debootstrap; takes a full image build the first
# time (the cache directory keeps the base and the layers for the next).
# Usage: tests/deploy/docker/image_test.sh [--cache-dir DIR] [--no-build]
#   --cache-dir DIR  build_image.sh's cache (env VANTAGE_IMAGE_CACHE;
#                    default build/image-cache of the repository)
#   --no-build       test the image already in the cache
# Env: VANTAGE_IMAGE_MAX_MB, the bound on the image's size (default 1150).
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
cache_dir="${VANTAGE_IMAGE_CACHE:-${repo_root}/build/image-cache}"
tag="localhost/vantage:latest"
max_mb="${VANTAGE_IMAGE_MAX_MB:-1150}"
build=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --cache-dir)
      [[ $# -ge 2 && -n "$2" ]] || { echo "image_test: --cache-dir needs a value" >&2; exit 2; }
      cache_dir="$2"; shift 2 ;;
    --no-build) build=0; shift ;;
    -h|--help) sed -n '2,19p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "image_test: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

fail() { echo "image_test: FAIL: $*" >&2; exit 1; }
[[ "${max_mb}" =~ ^[0-9]+$ ]] || fail "VANTAGE_IMAGE_MAX_MB must be a number of MB, not '${max_mb}'"
command -v buildah >/dev/null || fail "buildah is missing (apt-get install buildah)"

if [[ "${build}" -eq 1 ]]; then
  start=$(date +%s)
  "${repo_root}/deploy/docker/build_image.sh" --cache-dir "${cache_dir}" --tag "${tag}" ||
    fail "deploy/docker/build_image.sh failed (output above)"
  echo "image_test: image built in $(( $(date +%s) - start ))s"
fi
[[ -f "${cache_dir}/storage.conf" ]] ||
  fail "no ${cache_dir}/storage.conf: build the image first (without --no-build)"
mkdir -p "${cache_dir}/tmp"
export CONTAINERS_STORAGE_CONF="${cache_dir}/storage.conf"
export TMPDIR="${cache_dir}/tmp"
buildah inspect --type image "${tag}" >/dev/null 2>&1 || fail "no image ${tag} in ${cache_dir}"

containers=()
cleanup() {
  local c
  for c in "${containers[@]}"; do
    buildah rm "${c}" >/dev/null 2>&1 || echo "image_test: could not remove container ${c}" >&2
  done
  "${repo_root}/deploy/docker/unmount_cache.sh" "${cache_dir}" || true
}
trap cleanup EXIT

# The image's configuration, as docker or podman would run it (Go's
# printing of the values: buildah 1.28's templates have no json function).
config() { buildah inspect --type image --format "{{.OCIv1.Config.$1}}" "${tag}"; }
[[ "$(config Entrypoint)" == "[vantage]" ]] || fail "entrypoint is $(config Entrypoint), not [vantage]"
[[ "$(config Cmd)" == "[help]" ]] || fail "command is $(config Cmd), not [help]"
[[ "$(config User)" == "10001:10001" ]] || fail "user is '$(config User)', not 10001:10001"
[[ "$(config WorkingDir)" == "/data" ]] || fail "working directory is '$(config WorkingDir)', not /data"

container="$(buildah from --pull-never "${tag}")" || fail "buildah from ${tag} failed"
containers+=("${container}")

# Runs a command in the container: its output in $out, its status in $status.
run() {
  set +e
  out="$(buildah run --isolation=chroot "${container}" -- "$@" 2>&1)"
  status=$?
  set -e
}
# Runs a command that must succeed.
must() {
  run "$@"
  [[ "${status}" -eq 0 ]] || { printf '%s\n' "${out}" >&2; fail "'$*' exited with ${status}"; }
}
has_line() { grep -qE "$1" <<<"${out}"; }

must id -u
[[ "${out}" == "10001" ]] || fail "commands run as uid '${out}', not the image's user 10001"

must vantage help
has_line '^  train ' || { printf '%s\n' "${out}" >&2; fail "'vantage help' lists no train command"; }

must vantage envs
for env in InvertedPendulum Hopper BulletHopper; do
  has_line "^${env} " || { printf '%s\n' "${out}" >&2; fail "'vantage envs' lists no ${env}"; }
done

start=$(date +%s)
must vantage train --mode=local --steps=4096 --run_dir=runs/t
has_line '^RESULT train ' || { printf '%s\n' "${out}" >&2; fail "'vantage train' printed no RESULT train line"; }
echo "image_test: $(grep -E '^RESULT train ' <<<"${out}") ($(( $(date +%s) - start ))s with the container's start)"
must stat -c %u /data/runs/t/progress.csv
[[ "${out}" == "10001" ]] || fail "the run directory in /data belongs to uid '${out}', not 10001"

for env in Hopper BulletHopper; do
  must vantage rollout --env="${env}" --episodes=1 --video="${env}.mp4"
  has_line '^RESULT rollout ' || { printf '%s\n' "${out}" >&2; fail "'vantage rollout --env=${env}' printed no RESULT rollout line"; }
  must test -s "${env}.mp4"
done

# No Python by default (deploy/docker/Dockerfile says why): the commands
# that need it say so.
run vantage plot runs/t --out=t.png
[[ "${status}" -ne 0 && "${out}" == */usr/bin/python3* ]] ||
  fail "'vantage plot' in an image without Python: exit ${status}, '${out}' (expected a failure naming /usr/bin/python3)"

# (The single-quoted $ below are the container's to expand.)
# shellcheck disable=SC2016
must sh -c 'readlink -f "$(ldd /usr/local/bin/vantage | awk "\$1 == \"libblas.so.3\" { print \$3 }")"'
[[ "${out}" == *openblas* ]] || fail "libblas.so.3 is '${out}', not OpenBLAS"

# shellcheck disable=SC2016
must dpkg-query -W -f '${Package}\n'
grep -qx 'libtorch1.13' <<<"${out}" || fail "dpkg-query in the image lists no libtorch1.13"
if grep -- '-dev$' <<<"${out}" >/dev/null; then
  fail "the image holds -dev packages: $(grep -- '-dev$' <<<"${out}" | tr '\n' ' ')"
fi
# shellcheck disable=SC2016
must sh -c 'for tool in gcc g++ cc c++ clang clang++ cmake ninja; do command -v "${tool}" || true; done'
[[ -z "${out}" ]] || fail "the image holds a compiler or build tool: $(tr '\n' ' ' <<<"${out}")"

# Python environments step in the image's embedded Python (with numpy): the
# example CartPole it carries.
must vantage rollout \
  --env=python:/usr/local/share/vantage/examples/python_envs/cartpole.py:make \
  --episodes=2 --seed=1
[[ "${out}" == *"RESULT rollout"* ]] || fail "a Python env did not roll out in the image: ${out}"
must ls /usr/local/share/vantage
[[ "$(tr '\n' ' ' <<<"${out}")" == "configs deploy examples " ]] ||
  fail "/usr/local/share/vantage holds '${out}', not only configs, deploy and examples"

size="$(buildah images --format '{{.Size}}' "${tag}")"
mountpoint="$(buildah mount "${container}")" || fail "buildah mount failed"
size_mb="$(du -sxm "${mountpoint}" | cut -f1)"
buildah umount "${container}" >/dev/null
(( size_mb <= max_mb )) ||
  fail "the image's files take ${size_mb} MB, over the bound of ${max_mb} MB (VANTAGE_IMAGE_MAX_MB)"
echo "image_test: PASS (${tag}: ${size} as buildah images counts it, ${size_mb} MB of files)"
