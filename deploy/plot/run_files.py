"""What `vantage plot` and `vantage experiment report` share: the reading of
a run directory's progress.csv, their one-line errors with the vantage
CLI's exit codes, and their entry code.

Only the standard library is used, so that either script can report a bad
command line before numpy or matplotlib is imported.
"""

import argparse
import csv
import math
import os
import sys

USAGE_ERROR = 2
RUNTIME_ERROR = 1


class CommandError(Exception):
  """A problem with the command line or the files it names: one line on
  stderr and exit `code` (2 unless the failure happened while running)."""

  def __init__(self, message, code=USAGE_ERROR):
    super().__init__(message)
    self.code = code


class ArgumentParser(argparse.ArgumentParser):
  """argparse that reports a bad command line as a CommandError (exit 2)
  rather than printing its own usage; `hint` ends the message."""

  def __init__(self, *args, hint="", **kwargs):
    super().__init__(*args, add_help=False, **kwargs)
    self._hint = hint

  def error(self, message):
    raise CommandError(f"{message}{self._hint}")


def read_progress(directory):
  """(columns, rows) of DIRECTORY/progress.csv, rows as lists of strings.

  A run still writing may have a torn last line: it is dropped, as are
  trailing blank lines. Any other row whose length differs from the
  header's is a damaged file and raises. An empty file gives ([], [])."""
  path = os.path.join(directory, "progress.csv")
  try:
    with open(path, newline="", encoding="utf-8") as f:
      lines = list(csv.reader(f))
  except (OSError, UnicodeDecodeError, csv.Error) as e:
    raise CommandError(f"{path}: cannot read it ({e})")
  if not lines or not any(lines[0]):
    return [], []
  columns = [c.strip() for c in lines[0]]
  rows = lines[1:]
  while rows and not any(rows[-1]):
    rows.pop()
  if rows and len(rows[-1]) != len(columns):
    rows.pop()
  for number, row in enumerate(rows, start=2):
    if len(row) != len(columns):
      raise CommandError(f"{path} line {number}: {len(row)} fields, the "
                         f"header has {len(columns)}")
  return columns, rows


def column_values(directory, columns, rows, column):
  """The floats of one progress.csv column (NaN where a row leaves it
  empty); a value that is not a number raises, naming its line."""
  index = columns.index(column)
  values = []
  for number, row in enumerate(rows, start=2):
    text = row[index].strip()
    if not text:
      values.append(math.nan)
      continue
    try:
      values.append(float(text))
    except ValueError:
      raise CommandError(f"{os.path.join(directory, 'progress.csv')} line "
                         f"{number}: {column}={text!r} is not a "
                         f"number") from None
  return values


def run(prog, main, debug_variable):
  """Runs main(argv) as a command: its return value is the exit code, a
  CommandError is one line and its code, an unexpected exception one line
  and exit 1 (its traceback when the environment sets debug_variable)."""
  try:
    sys.exit(main(sys.argv[1:]))
  except CommandError as e:
    print(f"{prog}: {e}", file=sys.stderr)
    sys.exit(e.code)
  except KeyboardInterrupt:
    sys.exit(130)
  except Exception as e:  # a bug: still one line, the details on request
    if os.environ.get(debug_variable):
      raise
    print(f"{prog}: internal error: {type(e).__name__}: {e} (set "
          f"{debug_variable}=1 for the traceback)", file=sys.stderr)
    sys.exit(RUNTIME_ERROR)
