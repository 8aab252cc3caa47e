#!/usr/bin/python3
"""The report of an experiment directory made by `vantage experiment run`.

`vantage experiment report` executes this file with Debian's
/usr/bin/python3 and passes its arguments through; `--help` prints USAGE.
Statistics come from scipy (python3-scipy), figures from the plotting
script (deploy/plot/plot_runs.py, matplotlib).

Exit codes follow the vantage CLI: 0 done, 2 a usage error (flags, the
directory and the files in it), 1 a failure while running.
"""

import fnmatch
import json
import math
import os
import statistics
import sys
import warnings

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "plot"))
import plot_runs  # noqa: E402  (the figures; found beside this folder)
import run_files  # noqa: E402  (progress.csv, errors and entry, shared)

PROG = "vantage experiment report"
CONFIDENCE = 0.95
RESAMPLES = 10000
# The family-wise error rate of the report's tests (Holm), the power the
# minimum detectable effects are stated at, the effect the seed counts are
# for (a share of the baseline's mean final return), and the fewest seeds
# a group needs for a test.
ALPHA = 0.05
POWER = 0.8
RELATIVE_EFFECT = 0.10
MIN_SEEDS = 3
# Flags that place a cell or that the comparison is about: a group's
# baseline is the group with the same other settings.
NOT_MATCHED = {"env", "seed", "steps", "estimator", "rho", "ensemble"}

USAGE = """\
usage: vantage experiment report EXP_DIR [flags]

  Writes a Markdown report of the experiment in EXP_DIR (made by `vantage
  experiment run`): per env, a table of every group of cells (its
  settings but the seed) over its finished runs: the final return (the
  last progress.csv row's mean_return, the mean of the last 100 episodes)
  as mean +- sample sd and the number of runs, the area under the learning
  curve (as the mean return over training: the trapezoidal area under
  mean_return against env_steps divided by the steps it spans), the steps
  at which mean_return first reached the env's threshold (median over the
  runs that reached it), and the difference of the final return to the
  baseline group (the --baseline estimator with the same other settings)
  with a 95% percentile-bootstrap confidence interval (10,000 resamples
  of the seeds of each group, seeded, so reports repeat) and Welch's
  t-test p-value, and the difference of the areas with its interval (for
  tasks whose final returns all reach the maximum). The report's tests of
  final returns are one family: their p-values are adjusted by Holm's
  step-down method (family-wise error 0.05). Each comparison states its
  minimum detectable effect (the difference Welch's test would find with
  80% power at the family's strictest level, 0.05 / tests, from the two
  groups' measured standard deviations) and the seeds per group a 10%
  effect (of the baseline's mean) would need at that level. A group beats
  (or trails) the baseline "with confidence" when the interval excludes 0
  and the Holm-adjusted p < 0.05; the report says so in words. A group of
  fewer than 3 finished seeds gets no test (the report says so). A
  comparison counts the seeds both groups finished; a run of a seed the
  other group has not finished is left out, and the comparison says how
  many were (the groups of a pre-registered test run the same seeds). Every
  comparison names the CPU models that ran its groups (each run's
  machine.json): groups run on different models, or on unrecorded ones,
  are flagged in the verdict. Unfinished cells are listed, not counted. A
  summary table before the envs gives every group's verdict, difference
  [CI] and adjusted p on each env. One learning-curve figure per env
  (`vantage plot`) of its finished runs goes beside the report.
  Ends with a line `wrote FILE: E envs, G groups, R finished runs`.

flags:
  --out=EXP_DIR/report.md
      the Markdown file to write (its figures go to a figures/ folder
      beside it)
  --baseline=""
      the estimator every group is compared with (empty: the experiment's
      report.baseline, itself gae by default)
  --match=""
      comma-separated fields a group and its baseline must share besides
      the settings that are not the comparison's (rho, ensemble): e.g.
      --baseline=order:2 --match=rho tests each order statistic against
      the 2nd order at the same rho
  --baseline_set=""
      FLAG=VALUE[,FLAG=VALUE...]: the baseline is the --baseline
      estimator's group whose cells set these flags to these values, and a
      group may differ from it in them: e.g. --baseline_set=exploration=none
      tests every group (EX2 alone, max and min over EX2) against plain
      TRPO (gae without exploration)
  --groups=""
      comma-separated shell patterns: only the groups whose name matches
      one are tested (the others are listed, and their baselines still
      serve), so the family holds just the comparisons of a claim: e.g.
      --baseline=order:2 --match=rho --groups='order1-*,order4-*' tests
      min and max against the 2nd order and nothing else
  --threshold=""
      ENV=RETURN[,ENV=RETURN...]: the returns whose first crossing is
      reported (empty: the experiment's report.thresholds)
  --no_figures
      write the tables only
  --help
      this text

example:
  vantage experiment report experiments/mujoco --threshold=Hopper=1000
"""


ReportError = run_files.CommandError


def parse_arguments(argv):
  if any(a in ("--help", "-h", "-help") for a in argv):
    print(USAGE, end="")
    sys.exit(0)
  parser = run_files.ArgumentParser(prog=PROG)
  parser.add_argument("exp_dir", nargs="?")
  parser.add_argument("--out", default="")
  parser.add_argument("--baseline", default="")
  parser.add_argument("--threshold", default="")
  parser.add_argument("--match", default="")
  parser.add_argument("--baseline_set", default="")
  parser.add_argument("--groups", default="")
  parser.add_argument("--no_figures", action="store_true")
  args = parser.parse_args(argv)
  if not args.exp_dir:
    raise ReportError("name the experiment directory: vantage experiment "
                      "report EXP_DIR")
  args.match = set(filter(None, args.match.split(",")))
  for field in args.match - {"rho", "ensemble"}:
    raise ReportError(f"--match={field}: only rho and ensemble can be "
                      f"matched (the other settings always are)")
  args.groups = [g for g in args.groups.split(",") if g]
  entries, args.baseline_set = args.baseline_set.split(","), {}
  for entry in filter(None, entries):
    flag, equals, value = entry.partition("=")
    if not flag or not equals or not value:
      raise ReportError(f"--baseline_set entry '{entry}' is not FLAG=VALUE")
    if flag in NOT_MATCHED:
      raise ReportError(f"--baseline_set={entry}: {flag} is not a setting "
                        f"to fix (--baseline names the estimator; env, "
                        f"seed, steps, rho and ensemble are never matched)")
    args.baseline_set[flag] = value
  args.thresholds = {}
  for entry in filter(None, args.threshold.split(",")):
    env, _, value = entry.partition("=")
    try:
      number = float(value)
    except ValueError:
      number = math.nan
    if not env or not math.isfinite(number):
      raise ReportError(f"--threshold entry '{entry}' is not ENV=RETURN")
    args.thresholds[env] = number
  return args


def read_experiment(exp_dir):
  path = os.path.join(exp_dir, "experiment.json")
  if not os.path.isdir(exp_dir):
    raise ReportError(f"no such directory: {exp_dir}")
  try:
    with open(path, encoding="utf-8") as f:
      experiment = json.load(f)
  except FileNotFoundError:
    raise ReportError(f"{exp_dir} holds no experiment.json (made by "
                      f"`vantage experiment run`)")
  except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
    raise ReportError(f"{path}: cannot read it ({e})")
  cells = experiment.get("cells") if isinstance(experiment, dict) else None
  if not isinstance(cells, list) or not cells:
    raise ReportError(f"{path}: lists no cells")
  for i, cell in enumerate(cells):
    if not isinstance(cell, dict):
      raise ReportError(f"{path}: cells[{i}] is not an object")
    for key in ("dir", "env", "group", "config"):
      if key not in cell:
        raise ReportError(f"{path}: cells[{i}] has no \"{key}\"")
    try:
      int(cell["config"]["training"]["steps"])
    except (KeyError, TypeError, ValueError):
      raise ReportError(f"{path}: cells[{i}] has no config.training.steps")
    if not isinstance(cell.get("flags", {}), dict):
      raise ReportError(f"{path}: cells[{i}].flags is not an object")
    if ".." in cell["dir"].split("/") or os.path.isabs(cell["dir"]):
      raise ReportError(f"{path}: cells[{i}].dir leaves the experiment")
  return experiment


def read_curve(run_dir):
  """(env_steps, mean_return) pairs of the rows with a return, or None."""
  if not os.path.isfile(os.path.join(run_dir, "progress.csv")):
    return None
  columns, rows = run_files.read_progress(run_dir)
  if not rows:
    return []
  for column in ("env_steps", "mean_return"):
    if column not in columns:
      raise ReportError(f"{os.path.join(run_dir, 'progress.csv')}: no "
                        f"{column} column")
  return list(zip(
      run_files.column_values(run_dir, columns, rows, "env_steps"),
      run_files.column_values(run_dir, columns, rows, "mean_return")))


def read_cpu_models(run_dir):
  """The CPU models that ran the run (its machine.json), or None when it
  has no record (a run of a vantage before machine.json)."""
  path = os.path.join(run_dir, "machine.json")
  try:
    with open(path, encoding="utf-8") as f:
      models = json.load(f).get("cpu_models")
  except FileNotFoundError:
    return None
  except (OSError, UnicodeDecodeError, json.JSONDecodeError,
          AttributeError) as e:
    raise ReportError(f"{path}: cannot read it ({e})")
  if (not isinstance(models, list) or not models or
      not all(isinstance(m, str) for m in models)):
    raise ReportError(f"{path}: \"cpu_models\" is not a list of names")
  return models


class RunResult:

  def __init__(self, cell, curve, cpu_models=None):
    self.cell = cell
    self.curve = curve
    self.cpu_models = cpu_models
    steps = int(cell["config"]["training"]["steps"])
    self.finished = bool(curve) and curve[-1][0] >= steps
    finite = [(x, y) for x, y in curve or [] if math.isfinite(y)]
    self.final = curve[-1][1] if curve else math.nan
    if len(finite) >= 2 and finite[-1][0] > finite[0][0]:
      area = sum((x1 - x0) * (y0 + y1) / 2
                 for (x0, y0), (x1, y1) in zip(finite, finite[1:]))
      self.auc = area / (finite[-1][0] - finite[0][0])
    else:
      self.auc = finite[0][1] if finite else math.nan

  def steps_to(self, threshold):
    for x, y in self.curve:
      if math.isfinite(y) and y >= threshold:
        return x
    return None


def group_key(cell, matched=frozenset(), ignored=frozenset()):
  """What a group's baseline must share with it."""
  flags = cell.get("flags", {})
  skipped = (NOT_MATCHED - matched) | ignored
  return tuple(sorted((k, v) for k, v in flags.items() if k not in skipped))


def estimator_of(cell):
  return cell["config"].get("advantage", {}).get("estimator", "gae")


class Baseline:
  """What every group is compared with: an estimator's group, and with
  --baseline_set one whose cells set those flags so (in which the other
  groups may differ from it)."""

  def __init__(self, estimator, settings=None):
    self.estimator = estimator
    self.settings = dict(settings or {})

  def holds(self, cell):
    flags = cell.get("flags", {})
    return estimator_of(cell) == self.estimator and all(
        flags.get(k) == v for k, v in self.settings.items())

  def fixed(self):
    return ", ".join(f"{k}={v}" for k, v in sorted(self.settings.items()))

  def label(self):
    return (f"{self.estimator} ({self.fixed()})" if self.settings
            else self.estimator)


def mean_sd(values):
  import numpy as np
  if not values:
    return math.nan, math.nan
  sd = float(np.std(values, ddof=1)) if len(values) > 1 else math.nan
  return float(np.mean(values)), sd


def compare(values, baseline):
  """(difference of means, CI low, CI high, Welch p); NaNs where a group
  has fewer than MIN_SEEDS values."""
  import numpy as np
  from scipy import stats
  if not values or not baseline:  # no seed both groups finished
    return math.nan, math.nan, math.nan, math.nan
  difference = float(np.mean(values) - np.mean(baseline))
  if min(len(values), len(baseline)) < MIN_SEEDS:
    return difference, math.nan, math.nan, math.nan
  result = stats.bootstrap(
      (np.asarray(values), np.asarray(baseline)),
      lambda a, b, axis: np.mean(a, axis=axis) - np.mean(b, axis=axis),
      vectorized=True, paired=False, confidence_level=CONFIDENCE,
      n_resamples=RESAMPLES, method="percentile",
      random_state=np.random.default_rng(0))
  low = float(result.confidence_interval.low)
  high = float(result.confidence_interval.high)
  # Equal returns on both sides (a task's maximum) leave no variance: the
  # p-value is then NaN, which the words say, without scipy's warning.
  with np.errstate(all="ignore"), warnings.catch_warnings():
    warnings.simplefilter("ignore")
    p = float(stats.ttest_ind(values, baseline, equal_var=False).pvalue)
  return difference, low, high, p


def holm(p_values):
  """Holm's step-down adjustment of a family of p-values (NaN ones are no
  test and stay NaN)."""
  tested = sorted((p, i) for i, p in enumerate(p_values) if math.isfinite(p))
  adjusted = [math.nan] * len(p_values)
  running = 0.0
  for rank, (p, i) in enumerate(tested):
    running = max(running, min(1.0, (len(tested) - rank) * p))
    adjusted[i] = running
  return adjusted


def detectable(values, baseline, tests):
  """(minimum detectable effect, seeds per group for a RELATIVE_EFFECT
  effect) of Welch's test at level ALPHA / tests with POWER, from the
  groups' sample standard deviations; NaN where they do not say."""
  from scipy import stats
  if min(len(values), len(baseline)) < MIN_SEEDS or tests < 1:
    return math.nan, math.nan
  var_a = statistics.variance(values)
  var_b = statistics.variance(baseline)
  se2 = var_a / len(values) + var_b / len(baseline)
  if se2 <= 0:
    return math.nan, math.nan
  df = se2 ** 2 / ((var_a / len(values)) ** 2 / (len(values) - 1) +
                   (var_b / len(baseline)) ** 2 / (len(baseline) - 1))
  level = ALPHA / tests
  mde = (stats.t.ppf(1 - level / 2, df) + stats.t.ppf(POWER, df)) * \
      math.sqrt(se2)
  effect = RELATIVE_EFFECT * abs(statistics.mean(baseline))
  if effect <= 0:
    return float(mde), math.nan
  z = stats.norm.ppf(1 - level / 2) + stats.norm.ppf(POWER)
  seeds = math.ceil(z * z * (var_a + var_b) / (effect * effect))
  return float(mde), float(max(seeds, MIN_SEEDS))


def cpu_names(runs):
  """The CPU models of a group's runs, sorted; None if a run has none."""
  if any(r.cpu_models is None for r in runs):
    return None
  return sorted({m for r in runs for m in r.cpu_models})


def number(value, digits=1):
  if value is None or not math.isfinite(value):
    return "n/a"
  return f"{value:,.{digits}f}"


def signed(value):
  return "n/a" if not math.isfinite(value) else f"{value:+,.1f}"


def verdict(difference, low, high, p):
  """From the interval and the Holm-adjusted p."""
  if not (math.isfinite(low) and math.isfinite(p)):
    return "unknown"
  if low > 0 and p < 0.05:
    return "better"
  if high < 0 and p < 0.05:
    return "worse"
  return "unclear"


class Comparison:
  """One group's final return and area against its baseline group's."""

  def __init__(self, group, base, runs, base_runs, left_out=0):
    self.group, self.base = group, base
    self.left_out = left_out  # finished runs of a seed the other lacks
    self.finals = [r.final for r in runs]
    self.base_finals = [r.final for r in base_runs]
    self.runs, self.base_runs = len(self.finals), len(self.base_finals)
    self.difference, self.low, self.high, self.p = compare(
        self.finals, self.base_finals)
    self.auc = compare([r.auc for r in runs], [r.auc for r in base_runs])
    self.cpus, self.base_cpus = cpu_names(runs), cpu_names(base_runs)
    self.adjust(self.p, 1)

  def adjust(self, p_holm, tests):
    """The family's verdict: its Holm-adjusted p among `tests` tests."""
    self.p_holm = p_holm
    self.mde, self.seeds = detectable(self.finals, self.base_finals, tests)
    self.kind = ("too few seeds"
                 if min(self.runs, self.base_runs) < MIN_SEEDS else
                 verdict(self.difference, self.low, self.high, self.p_holm))

  def cpu_problem(self):
    """Why the groups' machines make the comparison doubtful, or ""."""
    if self.cpus is None or self.base_cpus is None:
      return "CPU models unrecorded"
    if self.cpus != self.base_cpus or len(self.cpus) > 1:
      return (f"MIXED CPU models ({' + '.join(self.cpus)} vs "
              f"{' + '.join(self.base_cpus)})")
    return ""

  def label(self):
    problem = self.cpu_problem()
    return f"{self.kind} ({problem})" if problem else self.kind

  def interval(self):
    return (f"{signed(self.difference)} [{signed(self.low)}, "
            f"{signed(self.high)}]")

  def cells(self):
    difference, low, high, _ = self.auc
    cpus = ("unrecorded" if self.cpus is None
            else " + ".join(self.cpus))
    return [self.interval(), number(self.p, 3), number(self.p_holm, 3),
            number(self.mde), number(self.seeds, 0),
            f"{signed(difference)} [{signed(low)}, {signed(high)}]",
            cpus + (" ⚠" if self.cpu_problem() else "")]

  def sentence(self):
    problem = self.cpu_problem()
    warning = f" ⚠ {problem}: the difference may be the machines'." \
        if problem.startswith("MIXED") else (
            f" ({problem}.)" if problem else "")
    return self.verdict_sentence() + warning

  def verdict_sentence(self):
    group, base = f"`{self.group}`", f"`{self.base}`"
    counts = f"{self.runs} vs {self.base_runs} runs"
    if self.left_out:
      counts += (f" on the seeds both finished; {self.left_out} more "
                 f"{'run' if self.left_out == 1 else 'runs'} not counted")
    power = (f"; detectable with 80% power: {number(self.mde)}, a 10% "
             f"effect needs {number(self.seeds, 0)} seeds a group"
             if math.isfinite(self.mde) else "")
    stated = (f"{signed(self.difference)}, 95% CI [{signed(self.low)}, "
              f"{signed(self.high)}], p = {number(self.p, 3)}, Holm "
              f"{number(self.p_holm, 3)} ({counts}{power}).")
    if self.kind == "better":
      return f"{group} beats {base} with confidence: {stated}"
    if self.kind == "worse":
      return f"{group} is worse than {base} with confidence: {stated}"
    if self.kind == "unclear":
      return f"{group} is not distinguishable from {base}: {stated}"
    if min(self.runs, self.base_runs) < MIN_SEEDS:
      return (f"{group} vs {base}: {signed(self.difference)}; fewer than "
              f"{MIN_SEEDS} seeds in a group, so no test ({counts}).")
    return (f"{group} vs {base}: {signed(self.difference)}; every run of "
            f"both ended at the same return, so there is no test "
            f"({counts}).")


def adjust_family(comparisons):
  """Holm over every comparison of the report that has a test."""
  adjusted = holm([c.p for c in comparisons])
  tests = sum(1 for c in comparisons if math.isfinite(c.p))
  for comparison, p_holm in zip(comparisons, adjusted):
    comparison.adjust(p_holm, tests)


def table_header(baseline_name, threshold):
  header = ["group", "runs", "final return", "AUC (mean return)"]
  if threshold is not None:
    header.append(f"steps to {number(threshold)}")
  header += [f"final - {baseline_name} [95% CI]", "Welch p", "Holm p",
             "detectable (80%)", "seeds for 10%",
             f"AUC - {baseline_name} [95% CI]", "CPU models"]
  return ["| " + " | ".join(header) + " |",
          "|" + "|".join(["---"] * len(header)) + "|"]


def group_row(group, runs, total, threshold):
  """The cells of a group's row before its comparison."""
  mean, sd = mean_sd([r.final for r in runs])
  auc_mean, auc_sd = mean_sd([r.auc for r in runs])
  row = [f"`{group}`", f"{len(runs)}/{total}",
         f"{number(mean)} ± {number(sd)}",
         f"{number(auc_mean)} ± {number(auc_sd)}"]
  if threshold is not None:
    reached = [s for s in (r.steps_to(threshold) for r in runs)
               if s is not None]
    median = statistics.median(reached) if reached else None
    row.append(f"{number(median, 0)} ({len(reached)}/{len(runs)} reached)"
               if reached else f"not reached (0/{len(runs)})")
  return row


def seed_of(run):
  return str(run.cell.get("seed", run.cell["config"]["training"].get("seed")))


def seed_ranges(seeds):
  """'16-36' for 16, 17, ..., 36; '3, 5, 7-9' when there are gaps."""
  ranges = []
  for seed in sorted(seeds):
    if ranges and seed == ranges[-1][1] + 1:
      ranges[-1][1] = seed
    else:
      ranges.append([seed, seed])
  return ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in ranges)


def cell_list(runs):
  """The runs' directories, a group's runs as one entry with its seeds
  ('TwoDMaze/gae seeds 16-36 (21 runs)'): a grid in progress leaves
  dozens unfinished, one per seed."""
  by_group = {}
  for run in runs:
    group, _, name = run.cell["dir"].rpartition("/")
    seed = seed_of(run)
    if name == f"seed-{seed}" and seed.isdigit():
      by_group.setdefault(group, []).append(int(seed))
    else:
      by_group.setdefault(run.cell["dir"], None)
  entries = []
  for group, seeds in by_group.items():
    if seeds is None:
      entries.append(group)
    elif len(seeds) == 1:
      entries.append(f"{group}/seed-{seeds[0]}")
    else:
      entries.append(f"{group} seeds {seed_ranges(seeds)} ({len(seeds)} runs)")
  return ", ".join(entries)


def paired(runs, base_runs):
  """The runs of the seeds both groups finished, and how many others were
  left out: groups are compared on the same seeds (a grid still running, or
  committed cell by cell, has groups a seed ahead of others)."""
  common = {seed_of(r) for r in runs} & {seed_of(r) for r in base_runs}
  own = [r for r in runs if seed_of(r) in common]
  theirs = [r for r in base_runs if seed_of(r) in common]
  return own, theirs, len(runs) + len(base_runs) - len(own) - len(theirs)


class EnvResults:
  """An env's groups of cells, their finished runs and their comparisons
  with the baseline (adjusted later, with the whole report's family)."""

  def __init__(self, env, results, baseline, matched=frozenset(),
               tested=None):
    self.env, self.baseline = env, baseline
    self.matched = frozenset(matched)
    self.ignored = frozenset(baseline.settings)
    self.groups = {}
    for result in results:
      self.groups.setdefault(result.cell["group"], []).append(result)
    self.finished = {
        g: [r for r in rs if r.finished and math.isfinite(r.final)]
        for g, rs in self.groups.items()}
    self.baselines = {}
    for group, runs in self.groups.items():
      cell = runs[0].cell
      if baseline.holds(cell):
        self.baselines.setdefault(self.key(cell), group)
    self.order = sorted(self.groups, key=lambda g: (
        not baseline.holds(self.groups[g][0].cell), g))
    self.tested = tested or (lambda group: True)
    self.comparisons = {}
    for group in self.order:
      base = self.base_of(group)
      if base is not None and base != group and self.tested(group) and \
          self.finished[group] and self.finished[base]:
        self.comparisons[group] = Comparison(
            group, base, *paired(self.finished[group], self.finished[base]))

  def key(self, cell):
    return group_key(cell, self.matched, self.ignored)

  def base_of(self, group):
    return self.baselines.get(self.key(self.groups[group][0].cell))

  def runs(self):
    return sum(len(r) for r in self.finished.values())


def env_section(results, threshold, figure, figure_problem):
  """The env's Markdown lines."""
  env = results.env
  lines = [f"## {env}", ""]
  unfinished = [r for g in results.order
                for r in results.groups[g] if not r.finished]
  if figure:
    lines += [f"![learning curves on {env}]({figure})", ""]
    if any(r.curve for r in unfinished):
      drawn = sum(r.finished for rs in results.groups.values() for r in rs)
      lines += [f"The figure draws the {drawn} finished runs; unfinished "
                f"runs are not drawn.", ""]
  elif figure_problem:
    lines += [f"(No figure: {figure_problem}.)", ""]
  lines += table_header(results.baseline.label(), threshold)
  for group in results.order:
    runs = results.finished[group]
    row = group_row(group, runs, len(results.groups[group]), threshold)
    comparison = results.comparisons.get(group)
    if comparison is None:
      base = results.base_of(group)
      row += ["—" if base == group else "no baseline" if base is None
              else "not tested (--groups)" if not results.tested(group)
              else "no finished runs"] + [""] * 6
    else:
      row += comparison.cells()
    lines.append("| " + " | ".join(row) + " |")
  lines.append("")
  comparisons = [results.comparisons[g] for g in results.order
                 if g in results.comparisons]
  lines += [f"- {c.sentence()}" for c in comparisons] or [
      "- No group has a baseline to be compared with."]
  no_return = [r for g in results.order for r in results.groups[g]
               if r.finished and not math.isfinite(r.final)]
  if unfinished:
    lines += ["", f"Unfinished, not counted: {cell_list(unfinished)}."]
  if no_return:
    lines += ["", f"Finished without a completed episode in their last 100 "
              f"(no final return), not counted: {cell_list(no_return)}."]
  lines.append("")
  return lines


def summary_section(comparisons_by_env, baseline_name):
  """One table of every comparison: a group per row, an env per column."""
  envs = [env for env, c in comparisons_by_env.items() if c]
  if not envs:
    return []
  groups = sorted({c.group for env in envs for c in comparisons_by_env[env]})
  lines = [f"## Summary: final return against `{baseline_name}`", "",
           "Each cell: the verdict, the difference of the final returns "
           "[95% CI] and its Holm-adjusted p (details in the env's "
           "section).", "",
           "| group | " + " | ".join(envs) + " |",
           "|" + "|".join(["---"] * (len(envs) + 1)) + "|"]
  for group in groups:
    row = [f"`{group}`"]
    for env in envs:
      match = [c for c in comparisons_by_env[env] if c.group == group]
      row.append(f"{match[0].label()} {match[0].interval()}, Holm p "
                 f"{number(match[0].p_holm, 3)}" if match else "")
    lines.append("| " + " | ".join(row) + " |")
  tally, flagged = {}, {}
  for env in envs:
    for c in comparisons_by_env[env]:
      tally.setdefault(c.group, []).append(c.kind)
      if c.cpu_problem():
        flagged.setdefault(c.group, []).append(env)
  lines.append("")
  for group in groups:
    kinds = tally[group]
    counted = ", ".join(f"{kind} on {kinds.count(kind)}"
                        for kind in ("better", "worse", "unclear",
                                     "too few seeds", "unknown")
                        if kind in kinds)
    machines = (f" CPU models mixed or unrecorded on "
                f"{', '.join(flagged[group])}." if group in flagged else "")
    lines.append(f"- `{group}`: {counted} of {len(kinds)} envs.{machines}")
  lines.append("")
  return lines


def make_figure(exp_dir, results, path):
  """True when drawn, False when no run has rows yet, else why not. Only
  finished runs are drawn, as only they are counted: a group's curve ends
  at its shortest run, so one run in progress would cut it short."""
  runs = [r for g in results.order for r in results.groups[g] if r.curve]
  if not runs:
    return False
  run_dirs = [os.path.join(exp_dir, r.cell["dir"]) for r in runs
              if r.finished]
  if not run_dirs:
    return "no run has finished yet"
  try:
    plot_runs.main(run_dirs + [f"--out={path}", f"--title={results.env}"])
  except run_files.CommandError as e:
    return str(e)
  return True


def main(argv):
  args = parse_arguments(argv)
  experiment = read_experiment(args.exp_dir)
  report = experiment.get("report", {})
  baseline = Baseline(args.baseline or report.get("baseline") or "gae",
                      args.baseline_set)
  estimators = sorted({estimator_of(c) for c in experiment["cells"]})
  if args.baseline and args.baseline not in estimators:
    raise ReportError(f"--baseline={args.baseline}: no cell uses that "
                      f"estimator (the experiment's: {', '.join(estimators)})")
  if baseline.settings and not any(baseline.holds(c)
                                   for c in experiment["cells"]):
    raise ReportError(f"--baseline_set: no {baseline.estimator} cell sets "
                      f"{baseline.fixed()}")
  thresholds = dict(report.get("thresholds", {}))
  thresholds.update(args.thresholds)
  out = args.out or os.path.join(args.exp_dir, "report.md")
  out_dir = os.path.dirname(os.path.abspath(out))
  if not os.path.isdir(out_dir):
    raise ReportError(f"--out={out}: its directory does not exist")
  by_env = {}
  for cell in experiment["cells"]:
    run_dir = os.path.join(args.exp_dir, cell["dir"])
    curve = read_curve(run_dir)
    cpus = read_cpu_models(run_dir) if curve is not None else None
    by_env.setdefault(cell["env"], []).append(RunResult(cell, curve, cpus))
  for env in thresholds:
    if env not in by_env:
      raise ReportError(f"--threshold: no cell runs {env} (envs: "
                        f"{', '.join(sorted(by_env))})")
  name = experiment.get("name") or os.path.basename(
      os.path.normpath(args.exp_dir))
  lines = [f"# Experiment {name}", ""]
  if experiment.get("description"):
    lines += [experiment["description"], ""]
  budget = experiment.get("budget", 1)
  lines += [f"From `{experiment.get('file', '?')}` at budget {budget:g} "
            f"(every cell's steps x {budget:g}); "
            f"{len(experiment['cells'])} cells. Final return: the last "
            f"100 episodes' mean at the end of a run. Groups are compared "
            f"with `{baseline.label()}` by a 95% percentile bootstrap over "
            f"seeds and Welch's t-test; the report's tests are one family, "
            f"their p-values adjusted by Holm's method; \"with "
            f"confidence\" means the interval excludes 0 and the adjusted "
            f"p < 0.05. \"Detectable (80%)\": the difference the test "
            f"finds with 80% power at the family's strictest level; "
            f"\"seeds for 10%\": the seeds per group that a difference of "
            f"10% of the baseline's mean would need there. A group of fewer "
            f"than {MIN_SEEDS} seeds gets no test. Comparisons of groups "
            f"run on different CPU models (or unrecorded ones) are "
            f"flagged." + (f" Only the groups matching "
                           f"{', '.join(args.groups)} are tested: the "
                           f"family is theirs." if args.groups else ""), ""]
  groups = {c["group"] for c in experiment["cells"]}
  for pattern in args.groups:
    if not fnmatch.filter(groups, pattern):
      raise ReportError(f"--groups: no group matches '{pattern}'")
  tested = (lambda group: any(fnmatch.fnmatchcase(group, pattern)
                              for pattern in args.groups)) \
      if args.groups else None
  results = {env: EnvResults(env, by_env[env], baseline, args.match, tested)
             for env in sorted(by_env)}
  adjust_family([c for r in results.values() for c in r.comparisons.values()])
  sections = []
  for env, env_results in results.items():
    figure = problem = None
    if not args.no_figures:
      figure_path = os.path.join(out_dir, "figures", f"{env}.png")
      os.makedirs(os.path.dirname(figure_path), exist_ok=True)
      drawn = make_figure(args.exp_dir, env_results, figure_path)
      if drawn is True:
        figure = os.path.relpath(figure_path, out_dir)
      elif drawn:
        problem = drawn
    sections += env_section(env_results, thresholds.get(env), figure,
                            problem)
  groups_total = sum(len(r.groups) for r in results.values())
  runs_total = sum(r.runs() for r in results.values())
  lines += summary_section(
      {env: list(r.comparisons.values()) for env, r in results.items()},
      baseline.label()) + sections
  with open(out, "w", encoding="utf-8") as f:
    f.write("\n".join(lines))
  print(f"wrote {out}: {len(by_env)} envs, {groups_total} groups, "
        f"{runs_total} finished runs")
  return 0


if __name__ == "__main__":
  run_files.run(PROG, main, "VANTAGE_REPORT_DEBUG")
