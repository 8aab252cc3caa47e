#!/usr/bin/env bash
# Unmounts whatever is still mounted under an image cache directory of
# deploy/docker/build_image.sh: the overlay mounts and bind mounts a killed
# image build or image test leaves behind, which would make the directory
# (and the clone holding it) impossible to remove. Deepest first; a busy
# mount is detached lazily. Nothing mounted: nothing to do.
# Usage: deploy/docker/unmount_cache.sh CACHE_DIR
set -euo pipefail
[[ $# -eq 1 && -n "$1" ]] || { echo "unmount_cache.sh: usage: unmount_cache.sh CACHE_DIR" >&2; exit 2; }
[[ -d "$1" ]] || exit 0
cache_dir="$(cd "$1" && pwd -P)"
# Through buildah first where it can, so that its store records no mount
# that is gone; what it does not know of is unmounted directly.
if [[ -f "${cache_dir}/storage.conf" ]] && command -v buildah >/dev/null; then
  CONTAINERS_STORAGE_CONF="${cache_dir}/storage.conf" TMPDIR="${cache_dir}/tmp" \
    buildah unmount --all >/dev/null 2>&1 || true
fi
# /proc/self/mounts escapes spaces and the like as octal (\040).
mapfile -t targets < <(awk -v dir="${cache_dir}/" \
  'index($2, dir) == 1 { print $2 }' /proc/self/mounts | sort -r)
for target in "${targets[@]}"; do
  target="$(printf '%b' "${target}")"
  umount "${target}" 2>/dev/null || umount -l "${target}" ||
    echo "unmount_cache.sh: could not unmount ${target}" >&2
done
[[ ${#targets[@]} -eq 0 ]] || echo "unmount_cache.sh: unmounted ${#targets[@]} stale mounts under ${cache_dir}"
