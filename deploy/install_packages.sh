#!/usr/bin/env bash
# Installs the given Debian packages that are not installed yet (apt-get,
# through sudo when not root); the ones present are skipped. Shared by
# deploy/setup.sh and tests/fuzz/run_fuzzers.sh.
# Usage: deploy/install_packages.sh WHO PACKAGE...   (WHO prefixes messages)
set -euo pipefail
who="$1"
shift
missing=()
for pkg in "$@"; do
  if ! dpkg-query -W -f='${Status}' "${pkg}" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("${pkg}")
  fi
done
[[ ${#missing[@]} -eq 0 ]] && exit 0
echo "${who}: installing ${missing[*]}"
sudo_cmd=()
if [[ "$(id -u)" -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "${who}: need root or sudo to install ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq \
  --no-install-recommends "${missing[@]}"
