#!/usr/bin/env bash
# Writes docs/cli.md from the binary's own help, so the reference cannot
# drift from the code (command_line_test checks that it holds every
# command's help verbatim).
# Usage: docs/make_cli_docs.sh [BINARY (build/vantage)] [OUT (docs/cli.md)]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
binary="${1:-${root}/build/vantage}"
out="${2:-${root}/docs/cli.md}"
commands="$("${binary}" help | awk '/^commands:/ {on = 1; next} on && /^  / {print $1}' | grep -v '^help$')"
{
  echo "# Commands and flags"
  echo
  echo "Every command of \`vantage\`, as \`vantage help COMMAND\` prints it"
  echo "(written by \`docs/make_cli_docs.sh\`; a test fails when this file is"
  echo "out of date). A flag that is not a command's own is refused (exit 2);"
  echo "\`--flagfile=FILE\` reads flags from a file, one per line, with the"
  echo "same result as on the command line. Exit codes: 0 done, 1 failed"
  echo "while running, 2 a usage error (flags, values, files they name)."
  echo
  echo '```'
  "${binary}" help
  echo '```'
  for command in ${commands}; do
    echo
    echo "## vantage ${command}"
    echo
    echo '```'
    "${binary}" help "${command}"
    echo '```'
  done
} >"${out}"
