#!/usr/bin/python3
"""The report of an experiment directory made by `vantage experiment run`.

`vantage experiment report` executes this file with Debian's
/usr/bin/python3 and passes its arguments through; `--help` prints USAGE.
Statistics come from scipy (python3-scipy), figures from the plotting
script (deploy/plot/plot_runs.py, matplotlib).

Exit codes follow the vantage CLI: 0 done, 2 a usage error (flags, the
directory and the files in it), 1 a failure while running.
"""

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
  tasks whose final returns all reach the maximum). A group beats (or trails) the baseline "with
  confidence" when the interval excludes 0 and p < 0.05; the report says
  so in words. Unfinished cells are listed, not counted. A summary table
  before the envs gives every group's verdict, difference [CI] and p on
  each env. One learning-curve figure per env (`vantage plot`) goes
  beside the report.
  Ends with a line `wrote FILE: E envs, G groups, R finished runs`.

flags:
  --out=EXP_DIR/report.md
      the Markdown file to write (its figures go to a figures/ folder
      beside it)
  --baseline=""
      the estimator every group is compared with (empty: the experiment's
      report.baseline, itself gae by default)
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
  parser.add_argument("--no_figures", action="store_true")
  args = parser.parse_args(argv)
  if not args.exp_dir:
    raise ReportError("name the experiment directory: vantage experiment "
                      "report EXP_DIR")
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


class RunResult:

  def __init__(self, cell, curve):
    self.cell = cell
    self.curve = curve
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


def group_key(cell):
  """What a group's baseline must share with it."""
  flags = cell.get("flags", {})
  return tuple(sorted((k, v) for k, v in flags.items()
                      if k not in NOT_MATCHED))


def estimator_of(cell):
  return cell["config"].get("advantage", {}).get("estimator", "gae")


def mean_sd(values):
  import numpy as np
  if not values:
    return math.nan, math.nan
  sd = float(np.std(values, ddof=1)) if len(values) > 1 else math.nan
  return float(np.mean(values)), sd


def compare(values, baseline):
  """(difference of means, CI low, CI high, Welch p); NaNs where n < 2."""
  import numpy as np
  from scipy import stats
  difference = float(np.mean(values) - np.mean(baseline))
  if len(values) < 2 or len(baseline) < 2:
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


def number(value, digits=1):
  if value is None or not math.isfinite(value):
    return "n/a"
  return f"{value:,.{digits}f}"


def signed(value):
  return "n/a" if not math.isfinite(value) else f"{value:+,.1f}"


def verdict(difference, low, high, p):
  if not (math.isfinite(low) and math.isfinite(p)):
    return "unknown"
  if low > 0 and p < 0.05:
    return "better"
  if high < 0 and p < 0.05:
    return "worse"
  return "unclear"


class Comparison:
  """One group's final return and area against its baseline group's."""

  def __init__(self, group, base, runs, base_runs):
    self.group, self.base = group, base
    finals = [r.final for r in runs]
    base_finals = [r.final for r in base_runs]
    self.runs, self.base_runs = len(finals), len(base_finals)
    self.difference, self.low, self.high, self.p = compare(finals,
                                                           base_finals)
    self.auc = compare([r.auc for r in runs], [r.auc for r in base_runs])
    self.kind = verdict(self.difference, self.low, self.high, self.p)

  def interval(self):
    return (f"{signed(self.difference)} [{signed(self.low)}, "
            f"{signed(self.high)}]")

  def cells(self):
    difference, low, high, _ = self.auc
    return [self.interval(), number(self.p, 3),
            f"{signed(difference)} [{signed(low)}, {signed(high)}]"]

  def sentence(self):
    group, base = f"`{self.group}`", f"`{self.base}`"
    counts = f"{self.runs} vs {self.base_runs} runs"
    stated = (f"{signed(self.difference)}, 95% CI [{signed(self.low)}, "
              f"{signed(self.high)}], p = {number(self.p, 3)} ({counts}).")
    if self.kind == "better":
      return (f"{group} beats {base} with confidence: "
              f"{signed(self.difference)} final return, 95% CI "
              f"[{signed(self.low)}, {signed(self.high)}], p = "
              f"{number(self.p, 3)} ({counts}).")
    if self.kind == "worse":
      return f"{group} is worse than {base} with confidence: {stated}"
    if self.kind == "unclear":
      return f"{group} is not distinguishable from {base}: {stated}"
    if min(self.runs, self.base_runs) < 2:
      return (f"{group} vs {base}: {signed(self.difference)}; too few runs "
              f"for a confidence interval ({counts}).")
    return (f"{group} vs {base}: {signed(self.difference)}; every run of "
            f"both ended at the same return, so there is no test "
            f"({counts}).")


def table_header(baseline_name, threshold):
  header = ["group", "runs", "final return", "AUC (mean return)"]
  if threshold is not None:
    header.append(f"steps to {number(threshold)}")
  header += [f"final - {baseline_name} [95% CI]", "Welch p",
             f"AUC - {baseline_name} [95% CI]"]
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


def env_section(env, results, baseline_name, threshold, figure,
                figure_problem):
  """The env's Markdown lines, its group and finished-run counts and its
  comparisons with the baseline."""
  groups = {}
  for result in results:
    groups.setdefault(result.cell["group"], []).append(result)
  lines = [f"## {env}", ""]
  if figure:
    lines += [f"![learning curves on {env}]({figure})", ""]
  elif figure_problem:
    lines += [f"(No figure: {figure_problem}.)", ""]
  lines += table_header(baseline_name, threshold)
  finished = {g: [r for r in rs if r.finished and math.isfinite(r.final)]
              for g, rs in groups.items()}
  baselines = {}
  for group, runs in groups.items():
    cell = runs[0].cell
    if estimator_of(cell) == baseline_name:
      baselines.setdefault(group_key(cell), group)
  comparisons = []
  order = sorted(groups, key=lambda g: (estimator_of(
      groups[g][0].cell) != baseline_name, g))
  for group in order:
    runs = finished[group]
    row = group_row(group, runs, len(groups[group]), threshold)
    base = baselines.get(group_key(groups[group][0].cell))
    if base is None or base == group or not runs or not finished[base]:
      row += ["—" if base == group else "no baseline", "", ""]
    else:
      comparisons.append(Comparison(group, base, runs, finished[base]))
      row += comparisons[-1].cells()
    lines.append("| " + " | ".join(row) + " |")
  lines.append("")
  lines += [f"- {c.sentence()}" for c in comparisons] or [
      "- No group has a baseline to be compared with."]
  unfinished = [r.cell["dir"] for g in order for r in groups[g]
                if not r.finished]
  no_return = [r.cell["dir"] for g in order for r in groups[g]
               if r.finished and not math.isfinite(r.final)]
  if unfinished:
    lines += ["", f"Unfinished, not counted: {', '.join(unfinished)}."]
  if no_return:
    lines += ["", f"Finished without a completed episode in their last 100 "
              f"(no final return), not counted: {', '.join(no_return)}."]
  lines.append("")
  return lines, len(groups), sum(len(r) for r in finished.values()), \
      comparisons


def summary_section(comparisons_by_env, baseline_name):
  """One table of every comparison: a group per row, an env per column."""
  envs = [env for env, c in comparisons_by_env.items() if c]
  if not envs:
    return []
  groups = sorted({c.group for env in envs for c in comparisons_by_env[env]})
  lines = [f"## Summary: final return against `{baseline_name}`", "",
           "Each cell: the verdict, the difference of the final returns "
           "[95% CI] and Welch's p (details in the env's section).", "",
           "| group | " + " | ".join(envs) + " |",
           "|" + "|".join(["---"] * (len(envs) + 1)) + "|"]
  for group in groups:
    row = [f"`{group}`"]
    for env in envs:
      match = [c for c in comparisons_by_env[env] if c.group == group]
      row.append(f"{match[0].kind} {match[0].interval()}, p "
                 f"{number(match[0].p, 3)}" if match else "")
    lines.append("| " + " | ".join(row) + " |")
  tally = {}
  for env in envs:
    for c in comparisons_by_env[env]:
      tally.setdefault(c.group, []).append(c.kind)
  lines.append("")
  for group in groups:
    kinds = tally[group]
    counted = ", ".join(f"{kind} on {kinds.count(kind)}"
                        for kind in ("better", "worse", "unclear", "unknown")
                        if kind in kinds)
    lines.append(f"- `{group}`: {counted} of {len(kinds)} envs.")
  lines.append("")
  return lines


def make_figure(exp_dir, results, path, env):
  """True when drawn, False when no run has rows yet, else why not."""
  run_dirs = [os.path.join(exp_dir, r.cell["dir"]) for r in results
              if r.curve]
  if not run_dirs:
    return False
  try:
    plot_runs.main(run_dirs + [f"--out={path}", f"--title={env}"])
  except run_files.CommandError as e:
    return str(e)
  return True


def main(argv):
  args = parse_arguments(argv)
  experiment = read_experiment(args.exp_dir)
  report = experiment.get("report", {})
  baseline_name = args.baseline or report.get("baseline") or "gae"
  estimators = sorted({estimator_of(c) for c in experiment["cells"]})
  if args.baseline and args.baseline not in estimators:
    raise ReportError(f"--baseline={args.baseline}: no cell uses that "
                      f"estimator (the experiment's: {', '.join(estimators)})")
  thresholds = dict(report.get("thresholds", {}))
  thresholds.update(args.thresholds)
  out = args.out or os.path.join(args.exp_dir, "report.md")
  out_dir = os.path.dirname(os.path.abspath(out))
  if not os.path.isdir(out_dir):
    raise ReportError(f"--out={out}: its directory does not exist")
  by_env = {}
  for cell in experiment["cells"]:
    curve = read_curve(os.path.join(args.exp_dir, cell["dir"]))
    by_env.setdefault(cell["env"], []).append(RunResult(cell, curve))
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
            f"with `{baseline_name}` by a 95% percentile bootstrap over "
            f"seeds and Welch's t-test; \"with confidence\" means the "
            f"interval excludes 0 and p < 0.05.", ""]
  groups_total = runs_total = 0
  sections, comparisons = [], {}
  for env in sorted(by_env):
    figure = problem = None
    if not args.no_figures:
      figure_path = os.path.join(out_dir, "figures", f"{env}.png")
      os.makedirs(os.path.dirname(figure_path), exist_ok=True)
      drawn = make_figure(args.exp_dir, by_env[env], figure_path, env)
      if drawn is True:
        figure = os.path.relpath(figure_path, out_dir)
      elif drawn:
        problem = drawn
    section, groups, runs, comparisons[env] = env_section(
        env, by_env[env], baseline_name, thresholds.get(env), figure,
        problem)
    sections += section
    groups_total += groups
    runs_total += runs
  lines += summary_section(comparisons, baseline_name) + sections
  with open(out, "w", encoding="utf-8") as f:
    f.write("\n".join(lines))
  print(f"wrote {out}: {len(by_env)} envs, {groups_total} groups, "
        f"{runs_total} finished runs")
  return 0


if __name__ == "__main__":
  run_files.run(PROG, main, "VANTAGE_REPORT_DEBUG")
