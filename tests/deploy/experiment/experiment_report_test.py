#!/usr/bin/python3
"""Tests of `vantage experiment report` (deploy/experiment/report.py).

  /usr/bin/python3 tests/deploy/experiment/experiment_report_test.py \
      --vantage=build/vantage

The experiment directory is written by hand (experiment.json, config.json
and progress.csv of every cell) with returns chosen so that every number of
the report can be computed here independently: means, sample standard
deviations and areas by hand, Welch's t-test by integrating Student's t
density (and its quantiles by bisection on that integral), Holm's
adjustment by its definition, and the bootstrap interval from the exact
bootstrap distribution (every resample enumerated).
"""

import itertools
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
VANTAGE = os.path.join(REPO, "build", "vantage")

STEPS = 3000
# env -> group -> estimator, seeds' curves (mean_return at 1000, 2000 and
# 3000 steps; None: no episode had ended yet).
CURVES = {
    "Hopper": {
        "gae": ("gae", [[10, 50, 100], [20, 60, 110], [None, 70, 120]]),
        "max-rho0.4-E1-16-64-2048": (
            "max", [[30, 90, 130], [40, 100, 150], [50, 110, 170],
                    [60, 120]]),  # the last one is unfinished
    },
    "InvertedPendulum": {
        "gae": ("gae", [[50, 90, 95], [60, 80, 99], [55, 85, 97]]),
        "min-rho0.4-E1-16-64-2048": ("min", [[100, 200, 300],
                                             [50, 150, 310],
                                             [80, 180, 305]]),
    },
    # Two baseline seeds: no test.
    "Swimmer": {
        "gae": ("gae", [[10, 20, 30], [12, 22, 32]]),
        "max-rho0.4-E1-16-64-2048": ("max", [[15, 25, 35], [16, 26, 36],
                                             [17, 27, 37]]),
    },
}
# The CPU model of each cell's machine.json: "CPU A" unless named here;
# Swimmer's cells have none (runs of a vantage before machine.json).
CPU_B = ("InvertedPendulum", "min-rho0.4-E1-16-64-2048", 2)
UNRECORDED = "Swimmer"


def take_vantage_flag(argv):
  rest, path = [argv[0]], None
  for argument in argv[1:]:
    if argument.startswith("--vantage="):
      path = argument.split("=", 1)[1]
    else:
      rest.append(argument)
  argv[:] = rest
  return path


def write_experiment(root):
  cells = []
  for env, groups in CURVES.items():
    for group, (estimator, curves) in groups.items():
      for seed, curve in enumerate(curves):
        directory = f"{env}/{group}/seed-{seed}"
        config = {"mode": "local",
                  "training": {"env": env, "seed": str(seed),
                               "steps": str(STEPS)},
                  "advantage": {"estimator": estimator, "rho": 0.4},
                  "ppo": {}}
        flags = {"env": env, "seed": str(seed), "estimator": estimator}
        cells.append({"dir": directory, "env": env, "group": group,
                      "seed": str(seed), "flags": flags, "config": config})
        path = os.path.join(root, directory)
        os.makedirs(path)
        with open(os.path.join(path, "config.json"), "w") as f:
          json.dump(config, f)
        if env != UNRECORDED:
          cpu = "CPU B" if (env, group, seed) == CPU_B else "CPU A"
          with open(os.path.join(path, "machine.json"), "w") as f:
            json.dump({"cpu_models": [cpu]}, f)
        with open(os.path.join(path, "progress.csv"), "w") as f:
          f.write("env_steps,updates,mean_return,elapsed_s,sps\n")
          for i, value in enumerate(curve):
            shown = "" if value is None else str(value)
            f.write(f"{1000 * (i + 1)},{i + 1},{shown},1,1\n")
  with open(os.path.join(root, "experiment.json"), "w") as f:
    json.dump({"name": "handmade", "file": "handmade.json", "budget": 1,
               "report": {"baseline": "gae",
                          "thresholds": {"InvertedPendulum": 100}},
               "cells": cells}, f)


def mean(values):
  return sum(values) / len(values)


def sd(values):
  m = mean(values)
  return math.sqrt(sum((v - m) ** 2 for v in values) / (len(values) - 1))


def welch_p(a, b):
  """Two-sided p of Welch's t-test, by integrating Student's t density."""
  va, vb = sd(a) ** 2 / len(a), sd(b) ** 2 / len(b)
  t = abs(mean(a) - mean(b)) / math.sqrt(va + vb)
  df = (va + vb) ** 2 / (va ** 2 / (len(a) - 1) + vb ** 2 / (len(b) - 1))
  c = math.gamma((df + 1) / 2) / (math.sqrt(df * math.pi) * math.gamma(df / 2))

  def density(x):
    return c * (1 + x * x / df) ** (-(df + 1) / 2)

  # The tail beyond t, with x = t / u (u in (0, 1]) to make it finite.
  n = 200000
  h = 1.0 / n
  total = 0.0
  for i in range(n):
    u = (i + 0.5) * h
    total += density(t / u) * t / (u * u) * h
  return 2 * total


def t_tail(t, df, n=20000):
  """P(T > t) for Student's t with df degrees of freedom, t >= 0."""
  c = math.gamma((df + 1) / 2) / (math.sqrt(df * math.pi) * math.gamma(df / 2))
  if t == 0:
    return 0.5
  h = 1.0 / n
  return sum(c * (1 + (t / u) ** 2 / df) ** (-(df + 1) / 2) * t / (u * u) * h
             for u in ((i + 0.5) * h for i in range(n)))


def t_quantile(q, df):
  """The q-quantile (q >= 0.5) of Student's t, by bisection."""
  low, high = 0.0, 100.0
  for _ in range(50):
    middle = (low + high) / 2
    if 1 - t_tail(middle, df) < q:
      low = middle
    else:
      high = middle
  return (low + high) / 2


def z_quantile(q):
  low, high = 0.0, 10.0
  for _ in range(80):
    middle = (low + high) / 2
    if 0.5 * (1 + math.erf(middle / math.sqrt(2))) < q:
      low = middle
    else:
      high = middle
  return (low + high) / 2


def detectable(a, b, tests):
  """Minimum detectable effect (80% power, Welch, level 0.05 / tests) and
  seeds per group for 10% of b's mean, as the report defines them."""
  va, vb = sd(a) ** 2, sd(b) ** 2
  se2 = va / len(a) + vb / len(b)
  df = se2 ** 2 / ((va / len(a)) ** 2 / (len(a) - 1) +
                   (vb / len(b)) ** 2 / (len(b) - 1))
  level = 0.05 / tests
  mde = (t_quantile(1 - level / 2, df) + t_quantile(0.8, df)) * math.sqrt(se2)
  z = z_quantile(1 - level / 2) + z_quantile(0.8)
  seeds = math.ceil(z * z * (va + vb) / (0.1 * mean(b)) ** 2)
  return mde, max(seeds, 3)


def exact_bootstrap_interval(a, b):
  """The 2.5th and 97.5th percentiles of the exact bootstrap distribution
  of mean(a*) - mean(b*) (every resample with replacement, equally likely)."""
  differences = sorted(
      mean(ra) - mean(rb)
      for ra in itertools.product(a, repeat=len(a))
      for rb in itertools.product(b, repeat=len(b)))
  n = len(differences)
  return differences[int(0.025 * n)], differences[min(n - 1, int(0.975 * n))]


def parse_number(text):
  text = text.replace(",", "").replace("+", "")
  return math.nan if text == "n/a" else float(text)


def table_rows(report, env):
  section = report.split(f"## {env}\n", 1)[1].split("\n## ", 1)[0]
  rows = {}
  for line in section.splitlines():
    match = re.match(r"\| `([^`]+)` \| (.*) \|$", line)
    if match:
      rows[match.group(1)] = [c.strip() for c in match.group(2).split(" | ")]
  return section, rows


class ReportTest(unittest.TestCase):

  @classmethod
  def setUpClass(cls):
    cls.root = tempfile.mkdtemp(prefix="vantage-report-")
    cls.exp = os.path.join(cls.root, "exp")
    write_experiment(cls.exp)
    cls.result = subprocess.run([VANTAGE, "experiment", "report", cls.exp],
                                capture_output=True, text=True, timeout=300)
    with open(os.path.join(cls.exp, "report.md")) as f:
      cls.report = f.read()

  @classmethod
  def tearDownClass(cls):
    shutil.rmtree(cls.root, ignore_errors=True)

  def test_ends_with_a_summary_line(self):
    self.assertEqual(self.result.returncode, 0, self.result.stderr)
    self.assertEqual(
        self.result.stdout.strip().splitlines()[-1],
        f"wrote {self.exp}/report.md: 3 envs, 6 groups, 17 finished runs")

  def test_final_returns_areas_and_the_comparison_by_hand(self):
    section, rows = table_rows(self.report, "Hopper")
    gae_finals, max_finals = [100, 110, 120], [130, 150, 170]
    gae_areas = [(30 * 1000 + 75 * 1000) / 2000,
                 (40 * 1000 + 85 * 1000) / 2000,
                 (70 + 120) / 2]  # from the first row with a return
    max_areas = [(60 + 110) / 2, (70 + 125) / 2, (80 + 140) / 2]
    gae, biased = rows["gae"], rows["max-rho0.4-E1-16-64-2048"]
    self.assertEqual(gae[0], "3/3")
    self.assertEqual(biased[0], "3/4")  # the unfinished run is not counted
    for row, finals, areas in ((gae, gae_finals, gae_areas),
                               (biased, max_finals, max_areas)):
      final_mean, final_sd = map(parse_number, row[1].split(" ± "))
      self.assertAlmostEqual(final_mean, mean(finals), places=1)
      self.assertAlmostEqual(final_sd, sd(finals), places=1)
      area_mean, area_sd = map(parse_number, row[2].split(" ± "))
      self.assertAlmostEqual(area_mean, mean(areas), places=1)
      self.assertAlmostEqual(area_sd, sd(areas), places=1)
    self.assertEqual(gae[3], "—")
    match = re.fullmatch(r"(\S+) \[(\S+), (\S+)\]", biased[3])
    self.assertIsNotNone(match, biased[3])
    difference, low, high = map(parse_number, match.groups())
    self.assertAlmostEqual(difference, 40.0, places=1)
    exact_low, exact_high = exact_bootstrap_interval(max_finals, gae_finals)
    self.assertLess(abs(low - exact_low), 4, (low, exact_low))
    self.assertLess(abs(high - exact_high), 4, (high, exact_high))
    p = welch_p(max_finals, gae_finals)
    self.assertAlmostEqual(parse_number(biased[4]), p, places=3)
    # Holm over the report's two tests (Swimmer's has too few seeds):
    # InvertedPendulum's is far smaller, so this one keeps its p.
    p_other = welch_p([300, 310, 305], [95, 99, 97])
    self.assertAlmostEqual(parse_number(biased[5]),
                           max(2 * p_other, p), places=3)
    mde, seeds = detectable(max_finals, gae_finals, tests=2)
    self.assertAlmostEqual(parse_number(biased[6]), mde, places=0)
    self.assertEqual(parse_number(biased[7]), seeds)
    self.assertEqual(biased[9], "CPU A")
    match = re.fullmatch(r"(\S+) \[(\S+), (\S+)\]", biased[8])
    self.assertIsNotNone(match, biased[8])
    self.assertAlmostEqual(parse_number(match.group(1)),
                           mean(max_areas) - mean(gae_areas), places=1)
    exact_low, exact_high = exact_bootstrap_interval(max_areas, gae_areas)
    self.assertLess(abs(parse_number(match.group(2)) - exact_low), 4)
    self.assertLess(abs(parse_number(match.group(3)) - exact_high), 4)
    # p = 0.055: the interval excludes 0 but the test does not agree.
    self.assertIn("`max-rho0.4-E1-16-64-2048` is not distinguishable from "
                  "`gae`", section)
    self.assertIn(f"a 10% effect needs {seeds:,} seeds a group", section)
    self.assertIn("Unfinished, not counted: "
                  "Hopper/max-rho0.4-E1-16-64-2048/seed-3.", section)

  def test_threshold_and_a_confident_win(self):
    section, rows = table_rows(self.report, "InvertedPendulum")
    self.assertEqual(rows["gae"][3], "not reached (0/3)")
    # Reached at 1000, 2000 and 2000 steps: the median is 2000.
    minimum = rows["min-rho0.4-E1-16-64-2048"]
    self.assertEqual(minimum[3], "2,000 (3/3 reached)")
    finals, base = [300, 310, 305], [95, 99, 97]
    p = welch_p(finals, base)
    self.assertLess(2 * p, 0.05)
    self.assertAlmostEqual(parse_number(minimum[5]), p, places=3)
    self.assertAlmostEqual(parse_number(minimum[6]), 2 * p, places=3)
    match = re.fullmatch(r"(\S+) \[(\S+), (\S+)\]", minimum[4])
    self.assertIsNotNone(match, minimum[4])
    difference, low, high = map(parse_number, match.groups())
    self.assertAlmostEqual(difference, mean(finals) - mean(base), places=1)
    exact_low, exact_high = exact_bootstrap_interval(finals, base)
    self.assertLess(abs(low - exact_low), 2, (low, exact_low))
    self.assertLess(abs(high - exact_high), 2, (high, exact_high))
    self.assertIn("`min-rho0.4-E1-16-64-2048` beats `gae` with confidence: "
                  "+208.0, 95% CI", section)
    # One of its seeds ran on another CPU: said loudly.
    self.assertEqual(minimum[10], "CPU A + CPU B ⚠")
    self.assertIn("⚠ MIXED CPU models (CPU A + CPU B vs CPU A): the "
                  "difference may be the machines'.", section)

  def test_fewer_than_three_seeds_get_no_test(self):
    # Compared on the seeds both groups finished: max's seeds 0 and 1
    # (35, 36) against gae's (30, 32); max's seed 2 is left out.
    section, rows = table_rows(self.report, "Swimmer")
    biased = rows["max-rho0.4-E1-16-64-2048"]
    self.assertEqual(biased[3], "+4.5 [n/a, n/a]")
    self.assertEqual(biased[4:8], ["n/a", "n/a", "n/a", "n/a"])
    self.assertEqual(biased[9], "unrecorded ⚠")
    self.assertIn("`max-rho0.4-E1-16-64-2048` vs `gae`: +4.5; fewer than 3 "
                  "seeds in a group, so no test (2 vs 2 runs on the seeds "
                  "both finished; 1 more run not counted). (CPU models "
                  "unrecorded.)", section)

  def test_a_summary_of_every_comparison_before_the_envs(self):
    summary = self.report.split("## Summary: final return against `gae`\n",
                                1)[1].split("\n## ", 1)[0]
    self.assertLess(self.report.index("## Summary"),
                    self.report.index("## Hopper"))
    self.assertIn("| group | Hopper | InvertedPendulum | Swimmer |", summary)
    p_max = welch_p([130, 150, 170], [100, 110, 120])
    p_min = welch_p([300, 310, 305], [95, 99, 97])
    rows = {line.split(" | ")[0]: line for line in summary.splitlines()
            if line.startswith("| `")}
    max_row = rows["| `max-rho0.4-E1-16-64-2048`"].split(" | ")
    self.assertTrue(max_row[1].startswith("unclear +40.0 ["), max_row)
    self.assertTrue(max_row[1].endswith(f", Holm p {p_max:.3f}"), max_row)
    self.assertEqual(max_row[2], "")  # no such group on InvertedPendulum
    self.assertEqual(max_row[3], "too few seeds (CPU models unrecorded) "
                     "+4.5 [n/a, n/a], Holm p n/a |")
    min_row = rows["| `min-rho0.4-E1-16-64-2048`"].split(" | ")
    self.assertTrue(min_row[2].startswith(
        "better (MIXED CPU models (CPU A + CPU B vs CPU A)) +208.0 ["),
        min_row)
    self.assertTrue(min_row[2].endswith(f", Holm p {2 * p_min:.3f}"), min_row)
    self.assertIn("- `max-rho0.4-E1-16-64-2048`: unclear on 1, too few seeds "
                  "on 1 of 2 envs. CPU models mixed or unrecorded on "
                  "Swimmer.", summary)
    self.assertIn("- `min-rho0.4-E1-16-64-2048`: better on 1 of 1 envs. CPU "
                  "models mixed or unrecorded on InvertedPendulum.", summary)

  def test_figures_beside_the_report(self):
    for env in CURVES:
      path = os.path.join(self.exp, "figures", f"{env}.png")
      with open(path, "rb") as f:
        self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
      self.assertIn(f"![learning curves on {env}](figures/{env}.png)",
                    self.report)

  def test_a_figure_draws_the_finished_runs_alone(self):
    # Hopper's fourth max run stops short; drawn, it would cut the group's
    # curve at its last row. The plot's own line counts what it drew.
    hopper = os.path.join(self.exp, "figures", "Hopper.png")
    self.assertIn(f"wrote {hopper}: 2 groups, 1 panel, 6 runs\n",
                  self.result.stdout)
    self.assertIn("The figure draws the 6 finished runs; unfinished runs "
                  "are not drawn.", table_rows(self.report, "Hopper")[0])
    self.assertNotIn("The figure draws",
                     table_rows(self.report, "InvertedPendulum")[0])

  def test_no_figure_before_a_run_has_finished(self):
    exp = self.write_finals("none_finished", {
        "gae": ({"estimator": "gae"}, [100, 110, 120]),
        "max": ({"estimator": "max"}, [130, 140, 150])})
    for group in ("gae", "max"):
      for seed in range(3):
        with open(os.path.join(exp, f"Hopper/{group}/seed-{seed}",
                               "progress.csv"), "w") as f:
          f.write("env_steps,updates,mean_return,elapsed_s,sps\n"
                  "500,1,90,1,1\n")
    result = subprocess.run([VANTAGE, "experiment", "report", exp],
                            capture_output=True, text=True, timeout=300)
    self.assertEqual(result.returncode, 0, result.stderr)
    with open(os.path.join(exp, "report.md")) as f:
      self.assertIn("(No figure: no run has finished yet.)", f.read())
    self.assertFalse(os.path.exists(os.path.join(exp, "figures",
                                                 "Hopper.png")))

  def test_the_same_report_again(self):
    out = os.path.join(self.root, "again.md")
    result = subprocess.run([VANTAGE, "experiment", "report", self.exp,
                             f"--out={out}", "--no_figures"],
                            capture_output=True, text=True, timeout=300)
    self.assertEqual(result.returncode, 0, result.stderr)
    with open(out) as f:
      again = f.read()
    strip = lambda text: re.sub(r"!\[.*\n\n(The figure draws .*\n\n)?", "",
                                text)
    self.assertEqual(strip(again), strip(self.report))

  def test_bad_input_is_one_line_with_exit_2(self):
    cases = [
        ([os.path.join(self.root, "missing")], "no such directory"),
        ([self.root], "holds no experiment.json"),
        ([self.exp, "--threshold=Hopper"], "--threshold entry 'Hopper' is "
         "not ENV=RETURN"),
        ([self.exp, "--threshold=Ant=5"], "--threshold: no cell runs Ant"),
        ([self.exp, "--out=/no/such/dir/r.md"], "its directory does not "
         "exist"),
        ([self.exp, "--colour=red"], "unrecognized arguments"),
        ([self.exp, "--baseline=maxabs"], "--baseline=maxabs: no cell uses "
         "that estimator (the experiment's: gae, max, min)"),
    ]
    for args, message in cases:
      result = subprocess.run([VANTAGE, "experiment", "report"] + args,
                              capture_output=True, text=True, timeout=60)
      self.assertEqual(result.returncode, 2, (args, result.stderr))
      self.assertIn(message, result.stderr)
      self.assertEqual(result.stderr.count("\n"), 1, result.stderr)
      self.assertTrue(
          result.stderr.startswith("vantage experiment report: "))

  def test_progress_files_read_as_vantage_plot_reads_them(self):
    # A run killed while writing leaves a torn last line: dropped, so the
    # cell counts as unfinished. A short row before the last, or a return
    # that is not a number, is a damaged file: refused by its line.
    exp = os.path.join(self.root, "damaged")
    shutil.rmtree(exp, ignore_errors=True)
    write_experiment(exp)
    progress = os.path.join(exp, "Hopper", "gae", "seed-0", "progress.csv")
    with open(progress) as f:
      lines = f.read().splitlines()
    with open(progress, "w") as f:
      f.write("\n".join(lines[:-1] + [lines[-1][:4]]) + "\n")
    result = subprocess.run([VANTAGE, "experiment", "report", exp,
                             "--no_figures"],
                            capture_output=True, text=True, timeout=60)
    self.assertEqual(result.returncode, 0, result.stderr)
    with open(os.path.join(exp, "report.md")) as f:
      self.assertIn("Unfinished, not counted: Hopper/gae/seed-0", f.read())
    for damaged, message in [
        (lines[:2] + ["1000,1"] + lines[2:], "line 3: 2 fields, the header "
         "has 5"),
        (lines[:2] + ["2000,2,lots,1,1"] + lines[3:],
         "line 3: mean_return='lots' is not a number")]:
      with open(progress, "w") as f:
        f.write("\n".join(damaged) + "\n")
      result = subprocess.run([VANTAGE, "experiment", "report", exp,
                               "--no_figures"],
                              capture_output=True, text=True, timeout=60)
      self.assertEqual(result.returncode, 2, result.stderr)
      self.assertIn(f"{progress} {message}", result.stderr)
      self.assertEqual(result.stderr.count("\n"), 1, result.stderr)

  def write_finals(self, name, groups):
    """An experiment of one-row runs on Hopper: group -> (flags besides
    env and seed, final returns by seed)."""
    exp = os.path.join(self.root, name)
    shutil.rmtree(exp, ignore_errors=True)
    cells = []
    for group, (flags, values) in groups.items():
      for seed, final in enumerate(values):
        directory = f"Hopper/{group}/seed-{seed}"
        config = {"training": {"env": "Hopper", "seed": str(seed),
                               "steps": "1000"},
                  "advantage": {"estimator": flags["estimator"]}}
        if "rho" in flags:
          config["advantage"]["rho"] = float(flags["rho"])
        cells.append({"dir": directory, "env": "Hopper", "group": group,
                      "seed": str(seed), "config": config,
                      "flags": dict(flags, env="Hopper", seed=str(seed))})
        os.makedirs(os.path.join(exp, directory))
        with open(os.path.join(exp, directory, "config.json"), "w") as f:
          json.dump(config, f)
        with open(os.path.join(exp, directory, "progress.csv"), "w") as f:
          f.write(f"env_steps,updates,mean_return,elapsed_s,sps\n"
                  f"1000,1,{final},1,1\n")
    with open(os.path.join(exp, "experiment.json"), "w") as f:
      json.dump({"name": name, "cells": cells}, f)
    return exp

  def report_rows(self, exp, *flags):
    result = subprocess.run([VANTAGE, "experiment", "report", exp,
                             "--no_figures", *flags],
                            capture_output=True, text=True, timeout=60)
    self.assertEqual(result.returncode, 0, result.stderr)
    with open(os.path.join(exp, "report.md")) as f:
      return table_rows(f.read(), "Hopper")

  def refused(self, exp, flag, message):
    bad = subprocess.run([VANTAGE, "experiment", "report", exp, flag],
                         capture_output=True, text=True, timeout=60)
    self.assertEqual(bad.returncode, 2, bad.stderr)
    self.assertIn(message, bad.stderr)
    self.assertEqual(bad.stderr.count("\n"), 1, bad.stderr)

  def test_a_matched_baseline_shares_the_rho(self):
    # order:4 and order:2 at two rhos: with --match=rho each order:4 group
    # is compared with the order:2 group of its own rho.
    exp = self.write_finals("matched", {
        f"order{estimator[-1]}-rho{rho}": (
            {"estimator": estimator, "rho": rho}, values)
        for (estimator, rho), values in {
            ("order:2", "0.2"): [100, 110, 120],
            ("order:2", "0.8"): [200, 210, 220],
            ("order:4", "0.2"): [110, 120, 130],
            ("order:4", "0.8"): [250, 260, 270]}.items()})
    _, rows = self.report_rows(exp, "--baseline=order:2", "--match=rho")
    self.assertTrue(rows["order4-rho0.2"][3].startswith("+10.0 ["),
                    rows["order4-rho0.2"])
    self.assertTrue(rows["order4-rho0.8"][3].startswith("+50.0 ["),
                    rows["order4-rho0.8"])
    self.refused(exp, "--match=env",
                 "--match=env: only rho and ensemble can be matched")

  def test_groups_narrow_the_family_to_a_claim(self):
    # order:3 beside order:4, both against order:2: --groups='order4-*'
    # tests order:4 alone, so Holm adjusts over its 2 tests, not 4.
    finals = {"order2": [100, 110, 120], "order3": [100, 115, 125],
              "order4": [130, 140, 150]}
    exp = self.write_finals("groups", {
        f"{group}-rho{rho}": ({"estimator": f"order:{group[-1]}",
                               "rho": rho}, [v + shift for v in values])
        for group, values in finals.items()
        for rho, shift in (("0.2", 0), ("0.8", 5))})
    _, everything = self.report_rows(exp, "--baseline=order:2",
                                     "--match=rho")
    _, narrowed = self.report_rows(exp, "--baseline=order:2", "--match=rho",
                                   "--groups=order4-*")
    for rho in ("0.2", "0.8"):
      self.assertEqual(narrowed[f"order3-rho{rho}"][3],
                       "not tested (--groups)")
      self.assertEqual(narrowed[f"order2-rho{rho}"][3], "—")
      tested = narrowed[f"order4-rho{rho}"]
      full = everything[f"order4-rho{rho}"]
      self.assertEqual(tested[3:5], full[3:5])  # difference, interval, p
      # Both order:4 groups are 30 above order:2 with the same spreads:
      # equal p, each adjusted to 2p (4p among the 4 tests of everything).
      p = float(tested[4])
      self.assertLess(4 * p, 1)
      self.assertAlmostEqual(float(tested[5]), 2 * p, delta=2e-3)
      self.assertAlmostEqual(float(full[5]), 4 * p, delta=2e-3)
    self.refused(exp, "--groups=order5-*",
                 "--groups: no group matches 'order5-*'")

  def test_a_baseline_set_by_a_flag_other_groups_lack(self):
    # EX2 alone (gae), plain TRPO (gae, exploration=none) and max over EX2:
    # by default max is compared with EX2 alone and plain TRPO has no
    # baseline of its own settings; against exploration=none both EX2
    # groups are compared with plain TRPO.
    exp = self.write_finals("baseline_set", {
        "gae": ({"estimator": "gae"}, [-130, -140, -150]),
        "gae-exploration_none": (
            {"estimator": "gae", "exploration": "none"}, [-180, -190, -200]),
        "max": ({"estimator": "max"}, [-100, -110, -120])})
    header, rows = self.report_rows(exp)
    self.assertIn("final - gae [95% CI]", header)
    self.assertTrue(rows["max"][3].startswith("+30.0 ["), rows["max"])
    self.assertEqual(rows["gae-exploration_none"][3], "—")
    header, rows = self.report_rows(exp, "--baseline_set=exploration=none")
    self.assertIn("final - gae (exploration=none) [95% CI]", header)
    self.assertTrue(rows["gae"][3].startswith("+50.0 ["), rows["gae"])
    self.assertTrue(rows["max"][3].startswith("+80.0 ["), rows["max"])
    self.assertEqual(rows["gae-exploration_none"][3], "—")
    # Two tests in the family: the larger p doubles at most.
    p_gae, p_max = float(rows["gae"][4]), float(rows["max"][4])
    self.assertAlmostEqual(float(rows["max"][5]),
                           min(1, 2 * min(p_gae, p_max)), delta=2e-3)
    for flag, message in [
        ("--baseline_set=exploration", "--baseline_set entry 'exploration' "
         "is not FLAG=VALUE"),
        ("--baseline_set=rho=0.4", "--baseline_set=rho=0.4: rho is not a "
         "setting to fix"),
        ("--baseline_set=exploration=ex3", "--baseline_set: no gae cell "
         "sets exploration=ex3")]:
      self.refused(exp, flag, message)

  def test_groups_are_compared_on_the_seeds_both_finished(self):
    # max's seed 3 has finished, gae's has not (a grid committed cell by
    # cell): the comparison is of seeds 0-2, +30 (with seed 3: +95).
    exp = self.write_finals("paired", {
        "gae": ({"estimator": "gae"}, [100, 110, 120]),
        "max": ({"estimator": "max"}, [130, 140, 150, 400])})
    _, rows = self.report_rows(exp)
    self.assertEqual(rows["max"][0], "4/4")  # the group's own runs
    self.assertTrue(rows["max"][3].startswith("+30.0 ["), rows["max"])
    p = float(rows["max"][4])
    self.assertAlmostEqual(p, welch_p([130, 140, 150], [100, 110, 120]),
                           delta=1e-3)
    with open(os.path.join(exp, "report.md")) as f:
      self.assertIn("(3 vs 3 runs on the seeds both finished; 1 more run "
                    "not counted", f.read())
    # No seed in common: no test, and the report says why.
    with open(os.path.join(exp, "experiment.json")) as f:
      record = json.load(f)
    for cell in record["cells"]:
      if cell["group"] == "gae":
        cell["seed"] = str(int(cell["seed"]) + 10)
    with open(os.path.join(exp, "experiment.json"), "w") as f:
      json.dump(record, f)
    _, rows = self.report_rows(exp)
    self.assertEqual(rows["max"][3], "n/a [n/a, n/a]")
    with open(os.path.join(exp, "report.md")) as f:
      self.assertIn("no test (0 vs 0 runs on the seeds both finished; 7 more "
                    "runs not counted)", f.read())

  def test_unfinished_runs_are_listed_by_group_and_seed_ranges(self):
    # A grid in progress: a group's unfinished seeds are one entry.
    exp = self.write_finals("in_progress", {
        "gae": ({"estimator": "gae"}, [100, 110, 120, 130, 140, 150, 160]),
        "max": ({"estimator": "max"}, [130, 140, 150, 160])})
    for group, seed in [("gae", 1), ("gae", 2), ("gae", 3), ("gae", 5),
                        ("max", 2)]:
      with open(os.path.join(exp, f"Hopper/{group}/seed-{seed}",
                             "progress.csv"), "w") as f:
        f.write("env_steps,updates,mean_return,elapsed_s,sps\n"
                "500,1,90,1,1\n")
    _, rows = self.report_rows(exp)
    self.assertEqual(rows["gae"][0], "3/7")
    self.assertEqual(rows["max"][0], "3/4")
    with open(os.path.join(exp, "report.md")) as f:
      self.assertIn("Unfinished, not counted: Hopper/gae seeds 1-3, 5 "
                    "(4 runs), Hopper/max/seed-2.\n", f.read())

  def test_a_damaged_machine_record_is_named(self):
    exp = os.path.join(self.root, "damaged_machine")
    shutil.rmtree(exp, ignore_errors=True)
    write_experiment(exp)
    machine = os.path.join(exp, "Hopper", "gae", "seed-1", "machine.json")
    for text in ("{not json", '{"cpu_models": "CPU A"}'):
      with open(machine, "w") as f:
        f.write(text)
      result = subprocess.run([VANTAGE, "experiment", "report", exp,
                               "--no_figures"],
                              capture_output=True, text=True, timeout=60)
      self.assertEqual(result.returncode, 2, result.stderr)
      self.assertIn(machine, result.stderr)
      self.assertEqual(result.stderr.count("\n"), 1, result.stderr)


if __name__ == "__main__":
  VANTAGE = take_vantage_flag(sys.argv) or VANTAGE
  unittest.main()
