#!/usr/bin/env bash
# Installs the Debian packages of deploy/setup.sh (its `packages=( ... )`
# list, read from that script so that the list stays in one place) through
# deploy/install_packages.sh, without configuring or building: the image's
# build stage configures with options of its own. Once setup.sh can install
# its packages alone (a --packages-only option), the Dockerfile can call it
# and this file can go.
# Usage: deploy/docker/install_build_packages.sh
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
setup="${repo_root}/deploy/setup.sh"
if [[ "${1:-}" == "-h" || "${1:-}" == "--help" ]]; then
  sed -n '2,8p' "${BASH_SOURCE[0]}"
  exit 0
fi
[[ $# -eq 0 ]] || { echo "install_build_packages.sh: takes no arguments" >&2; exit 2; }
[[ -f "${setup}" ]] || { echo "install_build_packages.sh: ${setup} is missing" >&2; exit 1; }

# The array runs from the line that opens it to the first line that is a
# lone ')'; only that text is evaluated, nothing else of setup.sh runs.
list="$(sed -n '/^packages=(/,/^)/p' "${setup}")"
if [[ -z "${list}" || "$(tail -n 1 <<<"${list}")" != ")" ]]; then
  echo "install_build_packages.sh: no 'packages=( ... )' list in ${setup}" >&2
  exit 1
fi
packages=()
eval "${list}"
if [[ ${#packages[@]} -eq 0 ]]; then
  echo "install_build_packages.sh: the package list in ${setup} is empty" >&2
  exit 1
fi
exec "${repo_root}/deploy/install_packages.sh" install_build_packages.sh \
  "${packages[@]}"
