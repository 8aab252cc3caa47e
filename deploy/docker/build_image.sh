#!/usr/bin/env bash
# Builds vantage's container image (deploy/docker/Dockerfile) with buildah
# on a machine that reaches no container registry, only a Debian mirror:
#  1. debootstraps a minbase bookworm root file system from the mirror of
#     this machine's apt sources (cached: later builds skip it);
#  2. imports it as the base image localhost/debian:bookworm;
#  3. runs `buildah bud --isolation=chroot --layers` on the Dockerfile with
#     BASE_IMAGE set to that base (unchanged layers are reused).
# Everything (the root file system's tarball, buildah's image store,
# temporary files) stays under the cache directory; the store's
# configuration is CACHE_DIR/storage.conf: to use the image afterwards,
#   CONTAINERS_STORAGE_CONF=CACHE_DIR/storage.conf buildah from IMAGE
# Needs root (debootstrap, buildah mount) and the Debian packages buildah
# and debootstrap. With a registry, no script is needed:
#   docker build -f deploy/docker/Dockerfile -t vantage .
#
# Usage: deploy/docker/build_image.sh [options]
#   --cache-dir DIR       cache and image store (env VANTAGE_IMAGE_CACHE;
#                         default build/image-cache of the repository)
#   --tag NAME            the image's name (default localhost/vantage:latest)
#   --base NAME           the base image's name (default localhost/debian:bookworm)
#   --mirror URL          Debian mirror (default: the URIs of this machine's
#                         bookworm apt source, else http://deb.debian.org/debian)
#   --security-mirror URL mirror of bookworm-security (default: likewise,
#                         else http://deb.debian.org/debian-security)
#   --storage-driver D    overlay or vfs (env STORAGE_DRIVER; default: the
#                         store's, else overlay if the kernel mounts it in
#                         the cache directory, else vfs, slower and bigger)
#   --nice N              niceness of debootstrap and the build (default 19)
#   --ccache-dir DIR      a ccache cache the build stage compiles through,
#                         mounted at /ccache (default: this machine's, from
#                         `ccache --get-config cache_dir`, if ccache is
#                         installed: objects of the machine's builds of the
#                         same sources are reused)
#   --no-ccache           compile everything in the build stage
#   --build-arg K=V       passed to buildah bud (repeatable; see the Dockerfile)
#   --rebuild-base        debootstrap and import the base again
#   --no-cache            build every layer again
#   --base-only           stop once the base image is there
#   -h, --help            this text
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cache_dir="${VANTAGE_IMAGE_CACHE:-${repo_root}/build/image-cache}"
tag="localhost/vantage:latest"
base="localhost/debian:bookworm"
mirror=""
security_mirror=""
storage_driver="${STORAGE_DRIVER:-}"
niceness=19
ccache_dir=""
use_ccache=1
build_args=()
rebuild_base=0
no_cache=()
base_only=0

die() { echo "build_image.sh: $*" >&2; exit 1; }
need_value() { [[ $# -ge 2 && -n "$2" ]] || die "$1 needs a value (see --help)"; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --cache-dir) need_value "$@"; cache_dir="$2"; shift 2 ;;
    --tag) need_value "$@"; tag="$2"; shift 2 ;;
    --base) need_value "$@"; base="$2"; shift 2 ;;
    --mirror) need_value "$@"; mirror="$2"; shift 2 ;;
    --security-mirror) need_value "$@"; security_mirror="$2"; shift 2 ;;
    --storage-driver) need_value "$@"; storage_driver="$2"; shift 2 ;;
    --nice) need_value "$@"; niceness="$2"; shift 2 ;;
    --ccache-dir) need_value "$@"; ccache_dir="$2"; shift 2 ;;
    --no-ccache) use_ccache=0; shift ;;
    --build-arg) need_value "$@"; build_args+=(--build-arg "$2"); shift 2 ;;
    --rebuild-base) rebuild_base=1; shift ;;
    --no-cache) no_cache=(--no-cache); shift ;;
    --base-only) base_only=1; shift ;;
    -h|--help) sed -n '2,40p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "build_image.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

case "${storage_driver}" in
  ""|overlay|vfs) ;;
  *) die "--storage-driver must be overlay or vfs, not '${storage_driver}'" ;;
esac
[[ "${niceness}" =~ ^-?[0-9]+$ ]] || die "--nice needs an integer, not '${niceness}'"
[[ "$(id -u)" -eq 0 ]] || die "must run as root (debootstrap and buildah mount need it)"
for tool in buildah debootstrap tar; do
  command -v "${tool}" >/dev/null ||
    die "${tool} is missing (apt-get install buildah debootstrap)"
done

# The mirrors of this machine's bookworm sources (deb822 stanzas), so that
# debootstrap and every apt-get of the build reach Debian the way this
# machine does.
sources=/etc/apt/sources.list.d/debian.sources
source_uri() {  # the first URI of the stanza whose Suites list holds $1
  [[ -r "${sources}" ]] || return 0
  awk -v suite="$1" '
    function flush() {
      if (!found && uri != "" && (" " suites " ") ~ (" " suite " ")) {
        print uri; found = 1
      }
      uri = ""; suites = ""
    }
    /^[ \t]*#/ { next }
    /^[ \t]*$/ { flush(); next }
    tolower($1) == "uris:" { uri = $2 }
    tolower($1) == "suites:" { $1 = ""; suites = $0 }
    END { flush() }' "${sources}"
}
[[ -n "${mirror}" ]] || mirror="$(source_uri bookworm)"
[[ -n "${mirror}" ]] || mirror="http://deb.debian.org/debian"
[[ -n "${security_mirror}" ]] || security_mirror="$(source_uri bookworm-security)"
[[ -n "${security_mirror}" ]] || security_mirror="http://deb.debian.org/debian-security"

mkdir -p "${cache_dir}"
cache_dir="$(cd "${cache_dir}" && pwd)"
# A build or test that was killed may have left its mounts behind.
"${repo_root}/deploy/docker/unmount_cache.sh" "${cache_dir}"
mkdir -p "${cache_dir}/tmp"

# The storage driver: a store keeps the one it was made with; a new one
# takes overlay where the kernel mounts it here (not on an overlay file
# system itself, e.g. inside a container), else vfs (full copies per layer).
store_driver=""
if [[ -d "${cache_dir}/storage" && -f "${cache_dir}/storage.conf" ]]; then
  store_driver="$(sed -n 's/^driver = "\(.*\)"$/\1/p' "${cache_dir}/storage.conf")"
fi
overlay_mounts() {
  local probe
  probe="$(mktemp -d "${cache_dir}/tmp/overlay-probe.XXXXXX")"
  mkdir "${probe}/lower" "${probe}/upper" "${probe}/work" "${probe}/merged"
  if mount -t overlay overlay -o "lowerdir=${probe}/lower,upperdir=${probe}/upper,workdir=${probe}/work" \
      "${probe}/merged" 2>/dev/null; then
    umount "${probe}/merged"
    rm -rf "${probe}"
    return 0
  fi
  rm -rf "${probe}"
  return 1
}
if [[ -z "${storage_driver}" ]]; then
  if [[ -n "${store_driver}" ]]; then
    storage_driver="${store_driver}"
  elif overlay_mounts; then
    storage_driver=overlay
  else
    storage_driver=vfs
    echo "build_image.sh: overlay does not mount in ${cache_dir}: using the vfs storage driver"
  fi
elif [[ -n "${store_driver}" && "${store_driver}" != "${storage_driver}" ]]; then
  die "the image store ${cache_dir}/storage uses ${store_driver}: remove it to switch to ${storage_driver}"
fi
# buildah's image store, its run state and its temporary files, all here;
# the system's /etc/containers/storage.conf and /var/lib/containers/storage
# are not touched.
cat >"${cache_dir}/storage.conf" <<EOF
[storage]
driver = "${storage_driver}"
graphroot = "${cache_dir}/storage"
runroot = "${cache_dir}/run"
EOF
export CONTAINERS_STORAGE_CONF="${cache_dir}/storage.conf"
export TMPDIR="${cache_dir}/tmp"
export BUILDAH_ISOLATION=chroot

elapsed() { echo "$(( $(date +%s) - $1 ))s"; }
# Unmounts what a debootstrap that stopped half way may have left mounted
# in its target (proc, sys), deepest first, before the target is removed.
unmount_under() {
  local dir="$1" target
  [[ -d "${dir}" ]] || return 0
  awk -v dir="${dir}" '$2 == dir || index($2, dir "/") == 1 { print $2 }' /proc/mounts |
    sort -r | while read -r target; do umount -l "${target}" || true; done
}

# 1. The root file system, as a tarball (written whole or not at all).
rootfs_tar="${cache_dir}/debian-bookworm-minbase.tar"
if [[ "${rebuild_base}" -eq 1 || ! -s "${rootfs_tar}" ]]; then
  rootfs="${cache_dir}/rootfs"
  unmount_under "${rootfs}"
  rm -rf "${rootfs}" "${rootfs_tar}" "${rootfs_tar}.partial"
  keyring=()
  if [[ -r /usr/share/keyrings/debian-archive-keyring.gpg ]]; then
    keyring=(--keyring=/usr/share/keyrings/debian-archive-keyring.gpg)
  fi
  echo "build_image.sh: debootstrap --variant=minbase bookworm from ${mirror}"
  start=$(date +%s)
  nice -n "${niceness}" debootstrap --variant=minbase "${keyring[@]}" \
      bookworm "${rootfs}" "${mirror}" >"${cache_dir}/debootstrap.log" 2>&1 || {
    unmount_under "${rootfs}"
    die "debootstrap failed (see ${cache_dir}/debootstrap.log)"
  }
  unmount_under "${rootfs}"
  # apt inside the image uses the same mirrors, with the security and
  # update suites as in Debian's own images.
  rm -f "${rootfs}/etc/apt/sources.list"
  cat >"${rootfs}/etc/apt/sources.list.d/debian.sources" <<EOF
Types: deb
URIs: ${mirror}
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: ${security_mirror}
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  rm -rf "${rootfs}"/var/cache/apt/archives/*.deb "${rootfs}"/var/lib/apt/lists/*
  tar --numeric-owner --xattrs -C "${rootfs}" -cf "${rootfs_tar}.partial" . ||
    die "cannot write ${rootfs_tar}.partial"
  mv "${rootfs_tar}.partial" "${rootfs_tar}"
  rm -rf "${rootfs}"
  echo "build_image.sh: debootstrap took $(elapsed "${start}")"
  rebuild_base=1
fi

# 2. The base image, from the tarball: a scratch container with it unpacked.
if [[ "${rebuild_base}" -eq 1 ]] || ! buildah inspect --type image "${base}" >/dev/null 2>&1; then
  start=$(date +%s)
  container="$(buildah from scratch)" || die "buildah from scratch failed"
  trap 'buildah rm "${container}" >/dev/null 2>&1 || true' EXIT
  mountpoint="$(buildah mount "${container}")" || die "buildah mount failed"
  tar --numeric-owner --xattrs -C "${mountpoint}" -xpf "${rootfs_tar}" ||
    die "cannot unpack ${rootfs_tar} into the base image"
  buildah umount "${container}" >/dev/null
  buildah config \
      --env PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
      --cmd bash --label "org.opencontainers.image.description=debootstrap --variant=minbase bookworm ${mirror}" \
      "${container}" || die "buildah config of the base failed"
  buildah commit --quiet --rm "${container}" "${base}" >/dev/null ||
    die "buildah commit of ${base} failed"
  trap - EXIT
  echo "build_image.sh: imported ${base} in $(elapsed "${start}")"
fi

[[ "${base_only}" -eq 0 ]] || exit 0

# 3. The image, compiled through this machine's ccache cache if there is one.
ccache_args=()
if [[ "${use_ccache}" -eq 1 ]]; then
  if [[ -z "${ccache_dir}" ]] && command -v ccache >/dev/null; then
    ccache_dir="$(ccache --get-config cache_dir)"
  fi
  if [[ -n "${ccache_dir}" ]]; then
    mkdir -p "${ccache_dir}"
    ccache_args=(--build-arg CCACHE=ON --volume "$(cd "${ccache_dir}" && pwd):/ccache")
    # ccache hashes these (they change the compiler's messages): the build
    # stage compiles with this caller's, as the machine's builds did.
    for variable in LANG LC_ALL LC_CTYPE LC_MESSAGES; do
      if [[ -n "${!variable+set}" ]]; then
        ccache_args+=(--build-arg "${variable}=${!variable}")
      fi
    done
  fi
fi
echo "build_image.sh: buildah bud -t ${tag} (BASE_IMAGE=${base}, storage ${storage_driver}, ccache ${ccache_dir:-none})"
start=$(date +%s)
nice -n "${niceness}" buildah bud --isolation=chroot --layers --pull-never \
    "${no_cache[@]}" --build-arg "BASE_IMAGE=${base}" "${ccache_args[@]}" "${build_args[@]}" \
    -t "${tag}" -f "${repo_root}/deploy/docker/Dockerfile" "${repo_root}" ||
  die "buildah bud failed (output above)"
echo "build_image.sh: built ${tag} in $(elapsed "${start}")"
echo "build_image.sh: use it with CONTAINERS_STORAGE_CONF=${cache_dir}/storage.conf"
