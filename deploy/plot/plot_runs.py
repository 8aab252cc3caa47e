#!/usr/bin/python3
"""Learning curves of vantage run directories, drawn like a paper's figures.

`vantage plot` executes this file with Debian's /usr/bin/python3 and passes
its arguments through unchanged; `vantage plot --help` prints USAGE below.
Only the standard library, numpy and matplotlib (python3-matplotlib) are used.

Exit codes follow the vantage CLI: 0 done, 2 a usage error (flags, values,
the directories and files they name), 1 a failure while running.
"""

import argparse
import json
import math
import os
import re
import sys
import warnings

import run_files  # beside this file: what `vantage experiment report` shares
from run_files import RUNTIME_ERROR

PROG = "vantage plot"

USAGE = """\
usage: vantage plot RUN_DIR... --out=FILE.png [flags]

  Draws learning curves from run directories (made by `vantage train
  --run_dir`): one curve per group of runs, the mean over its runs with a
  shaded band, one panel per value of --panel_by. A RUN_DIR may also hold
  runs at any depth (an experiment directory): every directory below it
  with config.json and progress.csv is a run. By default runs that differ
  only by their seed form a group, and a legend entry names what differs
  between the groups and how many runs it averages (n). Each group's runs
  are interpolated onto a common x grid over the range all of them cover
  (never extrapolated); empty (NaN) values are skipped. Ends with a line
  `wrote FILE: G groups, P panels, N runs`.

flags:
  --out=""
      the figure to write: .png (or .pdf, .svg); its directory must exist
  --x=env_steps
      the progress.csv column on the x axis
  --y=mean_return
      the progress.csv column on the y axis
  --group_by=""
      comma-separated fields whose values make a group (empty: every
      field but the seed). A field is a short name (env, algo, estimator,
      rho, ensemble, seed, horizon, steps, mode) or a config.json path
      (advantage.gae_lambda, ppo.learning_rate)
  --panel_by=""
      a field with one panel per value (e.g. env); empty: one panel, and
      runs of different envs are an error
  --band=sd
      sd (mean +- one sample standard deviation over the runs) | minmax
  --title=""
      the figure's title (empty: "Y vs X"; panels are titled by their value)
  --width=1200
      the figure's width in pixels (at 100 dpi)
  --height=800
      the figure's height in pixels (at 100 dpi)
  --flagfile=FILE
      more flags from FILE, one per line (same result as on the command line)
  --help
      this text

example:
  vantage plot runs/paper --panel_by=env --out=figure1.png
"""

SHORT_FIELDS = {
    "env": "training.env",
    "seed": "training.seed",
    "horizon": "training.horizon",
    "steps": "training.steps",
    "estimator": "advantage.estimator",
    "rho": "advantage.rho",
    "ensemble": "advantage.ensemble",
    "algo": "algo",
    "mode": "mode",
}
# What a short name means when no run's config.json holds it (protobuf JSON
# leaves out fields equal to their default).
SHORT_FIELD_DEFAULTS = {
    "training.env": "",
    "training.seed": 0,
    "training.horizon": 0,
    "training.steps": 0,
    "advantage.estimator": "",
    "advantage.rho": 0.0,
    "advantage.ensemble": (),
    "mode": "",
}
ALGORITHMS = ("ppo", "a2c", "trpo")
SEED = "training.seed"
# Fields that cannot change a learning curve, left out of the default
# grouping so that runs differing only in them still average together.
NOT_GROUPED_PREFIXES = ("recording.",)
# Preferred order of the fields a legend entry names.
LABEL_ORDER = ("training.env", "algo", "advantage.estimator", "advantage.rho",
               "advantage.ensemble")
# The default cycle (matplotlib's "tab10", C0..C9), fixed here so that the
# colours do not depend on a user's matplotlibrc.
COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
           "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")
LINESTYLES = ("-", "--", ":", "-.")
PRETTY_COLUMNS = {
    "env_steps": "Environment steps",
    "updates": "Updates",
    "policy_version": "Policy version",
    "episodes": "Episodes",
    "mean_return": "Mean return",
    "approx_kl": "Approximate KL",
    "elapsed_s": "Elapsed time (s)",
    "sps": "Environment steps per second",
}
MAX_GRID_POINTS = 2000
LINSPACE_POINTS = 1000
OUTPUT_FORMATS = (".png", ".pdf", ".svg")


# A problem with the command line or the runs it names (exit 2 unless
# raised while drawing).
PlotError = run_files.CommandError


class _NotApplicable:
  """The value of a field whose config section a run does not have."""

  def __repr__(self):
    return "n/a"

  def __eq__(self, other):
    return isinstance(other, _NotApplicable)

  def __hash__(self):
    return 0


NA = _NotApplicable()


def warn(message):
  print(f"{PROG}: warning: {message}", file=sys.stderr)


# ---------------------------------------------------------------- arguments


def _positive_pixels(name):
  def parse(text):
    try:
      value = int(text)
    except ValueError:
      raise argparse.ArgumentTypeError(
          f"--{name}={text}: not a whole number of pixels") from None
    if not 50 <= value <= 20000:
      raise argparse.ArgumentTypeError(
          f"--{name}={text}: must be between 50 and 20000 pixels")
    return value
  return parse


def expand_flagfiles(argv):
  """--flagfile=FILE: more flags from FILE, one per line, as every command."""
  expanded = []
  for argument in argv:
    if not argument.startswith("--flagfile="):
      expanded.append(argument)
      continue
    path = argument.split("=", 1)[1]
    try:
      with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError) as e:
      raise PlotError(f"--flagfile={path}: cannot read it ({e})")
    expanded.extend(line.strip() for line in lines
                    if line.strip() and not line.strip().startswith("#"))
  return expanded


def parse_arguments(argv):
  argv = expand_flagfiles(argv)
  if any(a in ("--help", "-h", "--helpfull") for a in argv):
    sys.stdout.write(USAGE)
    sys.exit(0)
  parser = run_files.ArgumentParser(prog=PROG, allow_abbrev=False,
                                    hint=" (see --help)")
  parser.add_argument("run_dirs", nargs="*", metavar="RUN_DIR")
  parser.add_argument("--out", default="")
  parser.add_argument("--x", default="env_steps")
  parser.add_argument("--y", default="mean_return")
  parser.add_argument("--group_by", default="")
  parser.add_argument("--panel_by", default="")
  parser.add_argument("--band", default="sd")
  parser.add_argument("--title", default="")
  parser.add_argument("--width", type=_positive_pixels("width"), default=1200)
  parser.add_argument("--height", type=_positive_pixels("height"),
                      default=800)
  args = parser.parse_args(argv)
  if not args.run_dirs:
    raise PlotError("no RUN_DIR given (see --help)")
  if not args.out:
    raise PlotError("--out=FILE is required (see --help)")
  if os.path.splitext(args.out)[1].lower() not in OUTPUT_FORMATS:
    raise PlotError(f"--out={args.out}: the file must end in "
                    + ", ".join(OUTPUT_FORMATS))
  parent = os.path.dirname(args.out) or "."
  if not os.path.isdir(parent):
    raise PlotError(f"--out={args.out}: no such directory: {parent}")
  if args.band not in ("sd", "minmax"):
    raise PlotError(f"--band={args.band}: must be sd or minmax")
  if not args.x or not args.y:
    raise PlotError("--x and --y must name a progress.csv column")
  return args


# --------------------------------------------------------------------- runs


class Run:

  def __init__(self, directory, fields, columns, rows):
    self.directory = directory
    self.fields = fields  # dotted config path -> canonical value
    self.columns = columns  # progress.csv header
    self.rows = rows  # lists of strings, one per progress.csv row


def find_runs(arguments):
  """The run directories named by or found below the arguments, in order."""
  found = []
  seen = set()

  def add(directory):
    key = os.path.realpath(directory)
    if key not in seen:
      seen.add(key)
      found.append(directory)

  def check_run(directory):
    has_config = os.path.isfile(os.path.join(directory, "config.json"))
    has_progress = os.path.isfile(os.path.join(directory, "progress.csv"))
    if has_config and not has_progress:
      raise PlotError(f"{directory}: a run without progress.csv")
    if has_progress and not has_config:
      raise PlotError(f"{directory}: a run without config.json")
    return has_config

  for argument in arguments:
    if not os.path.exists(argument):
      raise PlotError(f"no such directory: {argument}")
    if not os.path.isdir(argument):
      raise PlotError(f"not a directory: {argument}")
    if check_run(argument):
      add(argument)
      continue
    count = len(found)
    for directory, subdirectories, _ in os.walk(argument):
      subdirectories.sort()
      if directory != argument and check_run(directory):
        add(directory)
        subdirectories[:] = []  # a run's own folders hold no runs
    if len(found) == count:
      raise PlotError(f"no runs (directories with config.json and "
                      f"progress.csv) in {argument}")
  return found


def _canonical(value):
  """A hashable, comparable form: int64 strings as ints, lists as tuples."""
  if isinstance(value, bool) or value is None:
    return value
  if isinstance(value, (int, float)):
    return value
  if isinstance(value, str):
    return int(value) if re.fullmatch(r"-?\d+", value) else value
  if isinstance(value, list):
    return tuple(_canonical(v) for v in value)
  return json.dumps(value, sort_keys=True)


def _flatten(section, prefix, out):
  for key, value in section.items():
    path = prefix + key
    if isinstance(value, dict) and value:
      _flatten(value, path + ".", out)
    else:
      out[path] = _canonical(value)


_resolved_configs = None


def resolved_config(directory):
  """The run's config as the vantage that started this script resolves it
  (VANTAGE_RESOLVED_RUN_CONFIGS, deploy/cli/resolved_run_configs.h), or
  None (run as a script, or a config that vantage does not read): a run
  made before a setting existed records no value for it, and ran with the
  behaviour that setting's default keeps, not with the type's zero."""
  global _resolved_configs
  if _resolved_configs is None:
    _resolved_configs = {}
    path = os.environ.get("VANTAGE_RESOLVED_RUN_CONFIGS")
    if path:
      try:
        with open(path, encoding="utf-8") as f:
          _resolved_configs = json.load(f)
      except (OSError, ValueError) as e:
        warn(f"cannot read the resolved run configs ({e}): reading each "
             f"run's config.json as it is")
  return _resolved_configs.get(os.path.realpath(directory))


def read_config(directory):
  path = os.path.join(directory, "config.json")
  try:
    with open(path, encoding="utf-8") as f:
      config = json.load(f)
  except json.JSONDecodeError as e:
    raise PlotError(f"{path}: not valid JSON (line {e.lineno}: {e.msg})")
  except (OSError, UnicodeDecodeError) as e:
    raise PlotError(f"{path}: cannot read it ({e})")
  if not isinstance(config, dict):
    raise PlotError(f"{path}: not a JSON object")
  config = resolved_config(directory) or config
  if "training" not in config:
    raise PlotError(f"{path}: not a sectioned run config (no \"training\" "
                    f"section; an older flat config?): the plotting script "
                    f"reads only sectioned configs (`vantage plot` converts "
                    f"a flat one it can read)")
  algorithms = [a for a in ALGORITHMS if a in config]
  if len(algorithms) != 1:
    raise PlotError(f"{path}: must hold exactly one of the sections "
                    f"{', '.join(ALGORITHMS)}, holds "
                    f"{', '.join(algorithms) or 'none'}")
  fields = {}
  _flatten(config, "", fields)
  fields["algo"] = algorithms[0]
  return config, fields


def read_progress(directory):
  columns, rows = run_files.read_progress(directory)
  path = os.path.join(directory, "progress.csv")
  if not columns:
    raise PlotError(f"{path}: empty (no header, no rows)")
  if not rows:
    raise PlotError(f"{path}: no rows (the run has made no update yet)")
  return columns, rows


def load_runs(directories):
  runs = []
  configs = []
  for directory in directories:
    config, fields = read_config(directory)
    columns, rows = read_progress(directory)
    runs.append(Run(directory, fields, columns, rows))
    configs.append(config)
  # Protobuf JSON leaves out fields equal to their default: give a run the
  # default of the type other runs show, or n/a when it lacks the whole
  # section (another algorithm, no distributed settings in local mode).
  types = {}
  for run in runs:
    for path, value in run.fields.items():
      types.setdefault(path, value)
  for path, default in SHORT_FIELD_DEFAULTS.items():
    types.setdefault(path, default)
  for run, config in zip(runs, configs):
    for path, example in types.items():
      if path in run.fields:
        continue
      section = path.split(".")[0]
      if "." in path and section not in config:
        run.fields[path] = NA
      else:
        run.fields[path] = _default_like(example)
  return runs


def _default_like(value):
  if isinstance(value, bool):
    return False
  if isinstance(value, int):
    return 0
  if isinstance(value, float):
    return 0.0
  if isinstance(value, tuple):
    return ()
  if isinstance(value, str):
    return ""
  return NA


def column_values(run, column):
  return run_files.column_values(run.directory, run.columns, run.rows, column)


# ------------------------------------------------------------------- fields


def resolve_field(name, runs):
  """The dotted config path a --group_by/--panel_by name means."""
  name = name.strip()
  if name in SHORT_FIELDS:
    return SHORT_FIELDS[name]
  paths = sorted(runs[0].fields)  # every run holds every path by now
  if name in paths:
    return name
  matches = [p for p in paths if p.endswith("." + name)]
  if len(matches) == 1:
    return matches[0]
  if len(matches) > 1:
    raise PlotError(f"field {name!r} is ambiguous: one of "
                    f"{', '.join(matches)}")
  valid = list(SHORT_FIELDS) + [p for p in paths if p not in
                                SHORT_FIELDS.values()]
  raise PlotError(f"unknown field {name!r}; valid fields: "
                  f"{', '.join(valid)}")


def format_value(value):
  if value is NA:
    return "n/a"
  if isinstance(value, bool):
    return "true" if value else "false"
  if isinstance(value, float):
    if value.is_integer() and abs(value) < 1e15:
      return str(int(value))
    return repr(value)
  if isinstance(value, tuple):
    return "{" + ",".join(format_value(v) for v in value) + "}"
  if value == "":
    return '""'
  return str(value)


def field_text(path, value):
  """How a legend entry or a panel title names one field's value."""
  if path in ("training.env", "algo", "advantage.estimator", "mode"):
    return format_value(value)
  if path == "advantage.ensemble":
    return "E=" + format_value(value)
  short = {v: k for k, v in SHORT_FIELDS.items()}.get(path)
  return f"{short or path.split('.')[-1]}={format_value(value)}"


def sort_key(value):
  """Orders values of mixed types: numbers numerically, then the rest."""
  if value is NA:
    return (0, 0)
  if isinstance(value, bool):
    return (1, int(value))
  if isinstance(value, (int, float)):
    return (2, value)
  if isinstance(value, tuple):
    return (3, tuple(sort_key(v) for v in value))
  return (4, str(value))


def label_order(paths):
  preferred = [p for p in LABEL_ORDER if p in paths]
  return preferred + sorted(p for p in paths if p not in preferred)


# ----------------------------------------------------------------- grouping


class Group:

  def __init__(self, key):
    self.key = key  # tuple of values, one per grouping field
    self.runs = []
    self.label = ""
    self.colour = None
    self.linestyle = "-"


def arrange(runs, group_by, panel_by):
  """Panels (value -> runs) and the groups (key -> Group) of all runs."""
  panel_path = resolve_field(panel_by, runs) if panel_by else None
  explicit = ([resolve_field(f, runs) for f in group_by.split(",")
               if f.strip()] if group_by else [])

  envs = sorted({r.fields["training.env"] for r in runs}, key=sort_key)
  if (len(envs) > 1 and panel_path != "training.env" and
      "training.env" not in explicit):
    raise PlotError(f"runs of different envs "
                    f"({', '.join(format_value(e) for e in envs)}): pass "
                    f"--panel_by=env")

  panels = {}
  for run in runs:
    value = run.fields[panel_path] if panel_path else None
    panels.setdefault(value, []).append(run)
  panel_values = sorted(panels, key=sort_key)

  if explicit:
    key_paths = list(dict.fromkeys(explicit))
    label_paths = key_paths
  else:
    # A field makes groups when it varies within some panel: one that only
    # changes with the panel (each env's own step budget) does not split
    # the groups across panels, so a group keeps its colour in every one.
    key_paths = []
    for path in sorted(runs[0].fields):
      if (path == SEED or path == panel_path or
          path.startswith(NOT_GROUPED_PREFIXES)):
        continue
      if any(len({r.fields[path] for r in members}) > 1
             for members in panels.values()):
        key_paths.append(path)
    key_paths = label_order(key_paths)
    label_paths = key_paths

  groups = {}
  for run in runs:
    key = tuple(run.fields[p] for p in key_paths)
    groups.setdefault(key, Group(key)).runs.append(run)
  ordered = sorted(groups.values(),
                   key=lambda g: tuple(sort_key(v) for v in g.key))
  _label_groups(ordered, key_paths, label_paths, bool(explicit))
  for index, group in enumerate(ordered):
    group.colour = COLOURS[index % len(COLOURS)]
    group.linestyle = LINESTYLES[(index // len(COLOURS)) % len(LINESTYLES)]
  return panel_path, panel_values, panels, ordered


def _sections_present(groups, label_paths):
  """Splits off the paths that differ between groups only by their section
  being absent in some (a method's settings, e.g. exploration.ex2.*): those
  say no more than whether the section is there. Returns the other paths
  and, per such section, one of its paths."""
  kept, sections = [], {}
  for path in label_paths:
    values = [g.runs[0].fields[path] for g in groups]
    present = {format_value(v) for v in values if v is not NA}
    if "." in path and len(present) == 1 and len(present) < len(
        {format_value(v) for v in values}):
      sections.setdefault(path.rsplit(".", 1)[0], path)
    else:
      kept.append(path)
  return kept, sections


def _label_groups(groups, key_paths, label_paths, explicit):
  if not label_paths:
    # One group: name what it is rather than nothing.
    label_paths = ["algo", "advantage.estimator", "advantage.rho",
                   "advantage.ensemble"]
  label_paths, sections = _sections_present(groups, label_paths)

  def labels(simplify_gae):
    result = []
    for group in groups:
      first = group.runs[0].fields
      is_gae = all(r.fields["advantage.estimator"] == "gae"
                   for r in group.runs)
      parts = []
      for path in label_paths:
        # Without a biased statistic rho and the ensemble change nothing.
        if (simplify_gae and is_gae and
            path in ("advantage.rho", "advantage.ensemble")):
          continue
        parts.append(field_text(path, first[path]))
      for section, path in sections.items():
        name = section.split(".")[-1]
        parts.append(f"no {name}" if first[path] is NA else name)
      result.append(" ".join(parts))
    return result

  names = labels(simplify_gae=not explicit)
  if len(set(names)) < len(names):
    names = labels(simplify_gae=False)
  for group, name in zip(groups, names):
    group.label = name


# ------------------------------------------------------------------ curves


def group_curve(runs, x_column, y_column, band, np):
  """(x grid, mean, low, high) over the x range all runs cover, or None."""
  series = []
  for run in runs:
    x = np.asarray(column_values(run, x_column), dtype=float)
    y = np.asarray(column_values(run, y_column), dtype=float)
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if x.size == 0:
      warn(f"{run.directory}: no values of {y_column}; left out")
      continue
    # A resumed run repeats the updates after its checkpoint: the later row
    # of an x wins, then x ascends for the interpolation.
    last = {}
    for xi, yi in zip(x.tolist(), y.tolist()):
      last[xi] = yi
    xs = np.array(sorted(last), dtype=float)
    series.append((xs, np.array([last[v] for v in xs.tolist()])))
  if not series:
    return None
  low = max(s[0][0] for s in series)
  high = min(s[0][-1] for s in series)
  if low > high:
    warn(f"the runs of {runs[0].directory}'s group share no range of "
         f"{x_column}; its curve is left out")
    return None
  grid = np.unique(np.concatenate([s[0] for s in series]))
  grid = grid[(grid >= low) & (grid <= high)]
  if grid.size > MAX_GRID_POINTS:
    grid = np.linspace(low, high, LINSPACE_POINTS)
  values = np.vstack([np.interp(grid, xs, ys) for xs, ys in series])
  mean = values.mean(axis=0)
  if band == "minmax":
    lower, upper = values.min(axis=0), values.max(axis=0)
  elif len(series) > 1:
    sd = values.std(axis=0, ddof=1)
    lower, upper = mean - sd, mean + sd
  else:
    lower = upper = None
  return grid, mean, lower, upper, len(series)


def pretty_column(column):
  if column in PRETTY_COLUMNS:
    return PRETTY_COLUMNS[column]
  text = column.replace("_", " ")
  return text[:1].upper() + text[1:]


# -------------------------------------------------------------------- draw


def draw(args, runs, panel_path, panel_values, panels, groups):
  try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
  except ImportError as e:
    raise PlotError(f"matplotlib is not installed for {sys.executable} "
                    f"(Debian: apt-get install python3-matplotlib): {e}",
                    RUNTIME_ERROR)
  matplotlib.rcdefaults()
  matplotlib.rcParams.update({
      "font.size": 11,
      "axes.titlesize": 12,
      "axes.labelsize": 11,
      "legend.fontsize": 10,
      "axes.spines.top": False,
      "axes.spines.right": False,
      "axes.grid": True,
      "grid.alpha": 0.3,
      "grid.linewidth": 0.6,
  })

  group_of = {}
  for group in groups:
    for run in group.runs:
      group_of[id(run)] = group

  count = len(panel_values)
  rows = math.ceil(count / 4)
  cols = math.ceil(count / rows)
  dpi = 100
  fig, axes = plt.subplots(rows, cols, squeeze=False, dpi=dpi,
                           figsize=(args.width / dpi, args.height / dpi))
  x_label = pretty_column(args.x)
  y_label = pretty_column(args.y)
  title = args.title or f"{y_label} vs {x_label[:1].lower() + x_label[1:]}"

  drawn = {}  # group -> its run counts per panel, for the legend
  handles = {}
  runs_drawn = 0
  for index, value in enumerate(panel_values):
    ax = axes[index // cols][index % cols]
    members = panels[value]
    for group in groups:
      group_runs = [r for r in members if group_of[id(r)] is group]
      if not group_runs:
        continue
      curve = group_curve(group_runs, args.x, args.y, args.band, np)
      if curve is None:
        continue
      grid, mean, lower, upper, n = curve
      runs_drawn += n
      drawn.setdefault(id(group), set()).add(n)
      marker = "o" if grid.size == 1 else None
      (line,) = ax.plot(grid, mean, color=group.colour, lw=1.8,
                        ls=group.linestyle, marker=marker, zorder=3)
      handles[id(group)] = line
      if lower is not None:
        ax.fill_between(grid, lower, upper, color=group.colour, alpha=0.2,
                        lw=0, zorder=2)
    if count > 1:
      ax.set_title(field_text(panel_path, value))
    elif args.title:
      ax.set_title(args.title)
    else:
      where = field_text(panel_path, value) if panel_path else ", ".join(
          sorted({format_value(r.fields["training.env"]) for r in members}))
      ax.set_title(f"{title} ({where})")
    below = index + cols
    if below >= count:
      ax.set_xlabel(x_label)
    if index % cols == 0:
      ax.set_ylabel(y_label)
    ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 4),
                        useMathText=True)
    ax.margins(x=0.02)
  for index in range(count, rows * cols):
    axes[index // cols][index % cols].set_visible(False)

  if not handles:
    plt.close(fig)
    raise PlotError(f"no values of {args.y} against {args.x} in any run")

  legend_handles, legend_labels = [], []
  for group in groups:
    if id(group) not in handles:
      continue
    ns = sorted(drawn[id(group)])
    n = str(ns[0]) if len(ns) == 1 else f"{ns[0]}-{ns[-1]}"
    legend_handles.append(handles[id(group)])
    legend_labels.append(f"{group.label} (n={n})")

  with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # tight_layout on very small figures
    if count == 1:
      axes[0][0].legend(legend_handles, legend_labels, loc="best",
                        frameon=False)
      fig.tight_layout()
    else:
      fig.suptitle(title, fontsize=13)
      ncol = min(len(legend_labels), 4)
      legend_rows = math.ceil(len(legend_labels) / ncol)
      bottom = min(0.5, (legend_rows * 24 + 14) / args.height)
      fig.legend(legend_handles, legend_labels, loc="lower center",
                 ncol=ncol, frameon=False)
      fig.tight_layout(rect=(0, bottom, 1, 1))
    try:
      fig.savefig(args.out, dpi=dpi)
    except OSError as e:
      raise PlotError(f"--out={args.out}: cannot write it ({e.strerror})")
    finally:
      plt.close(fig)
  return len(legend_labels), count, runs_drawn


# -------------------------------------------------------------------- main


def plural(n, word):
  return f"{n} {word}" if n == 1 else f"{n} {word}s"


def main(argv):
  args = parse_arguments(argv)
  runs = load_runs(find_runs(args.run_dirs))
  common = [c for c in runs[0].columns
            if all(c in r.columns for r in runs[1:])]
  for flag, column in (("--x", args.x), ("--y", args.y)):
    if column not in common:
      raise PlotError(f"{flag}={column}: unknown column; valid columns: "
                      f"{', '.join(common)}")
  panel_path, panel_values, panels, groups = arrange(runs, args.group_by,
                                                     args.panel_by)
  g, p, n = draw(args, runs, panel_path, panel_values, panels, groups)
  print(f"wrote {args.out}: {plural(g, 'group')}, {plural(p, 'panel')}, "
        f"{plural(n, 'run')}")
  return 0


if __name__ == "__main__":
  run_files.run(PROG, main, "VANTAGE_PLOT_DEBUG")
