#!/usr/bin/python3
"""Tests of `vantage plot` (deploy/plot/plot_runs.py) on real short runs.

  /usr/bin/python3 tests/deploy/plot/plot_runs_test.py --vantage=build/vantage

plots with `VANTAGE plot ...`, or, with VANTAGE_PLOT_VIA_SCRIPT set, with
`/usr/bin/python3 deploy/plot/plot_runs.py ...` (the same arguments).
The runs are made once with `VANTAGE train --mode=local`.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
SCRIPT = os.path.join(REPO, "deploy", "plot", "plot_runs.py")
PYTHON = "/usr/bin/python3"
VANTAGE = os.path.join(REPO, "build", "vantage")

ESTIMATORS = ("gae", "max")
SEEDS = (1, 2)
STEPS = 3072
HORIZON = 512
# matplotlib's default cycle, which the plot uses for groups 0, 1, 2, 3.
C0, C1, C2, C3 = ((0x1f, 0x77, 0xb4), (0xff, 0x7f, 0x0e), (0x2c, 0xa0, 0x2c),
                  (0xd6, 0x27, 0x28))


def take_vantage_flag(argv):
  """Removes --vantage=PATH / --vantage PATH from argv; returns PATH."""
  path = None
  rest = [argv[0]]
  i = 1
  while i < len(argv):
    if argv[i].startswith("--vantage="):
      path = argv[i].split("=", 1)[1]
    elif argv[i] == "--vantage" and i + 1 < len(argv):
      path = argv[i + 1]
      i += 1
    else:
      rest.append(argv[i])
    i += 1
  argv[:] = rest
  return path


def plot(*args):
  if os.environ.get("VANTAGE_PLOT_VIA_SCRIPT"):
    command = [PYTHON, SCRIPT]
  else:
    command = [VANTAGE, "plot"]
  return subprocess.run(command + [str(a) for a in args], capture_output=True,
                        text=True, timeout=120)


def read_png(path):
  import matplotlib
  matplotlib.use("Agg")
  import matplotlib.image
  return matplotlib.image.imread(path)


def pixels_near(image, rgb, tolerance=12):
  """How many pixels are within `tolerance` (of 255) of `rgb` per channel."""
  import numpy as np
  target = np.array(rgb, dtype=float) / 255.0
  distance = np.abs(image[:, :, :3] - target).max(axis=2)
  return int((distance <= tolerance / 255.0).sum())


class PlotRunsTest(unittest.TestCase):

  @classmethod
  def setUpClass(cls):
    cls.root = tempfile.mkdtemp(prefix="plot_runs_test.")
    # Laid out like an experiment: EXP/<env>/<estimator>/seed-<s>.
    cls.experiment = os.path.join(cls.root, "exp")
    cls.runs = []
    for estimator in ESTIMATORS:
      for seed in SEEDS:
        run_dir = os.path.join(cls.experiment, "InvertedPendulum", estimator,
                               f"seed-{seed}")
        os.makedirs(os.path.dirname(run_dir), exist_ok=True)
        flags = [f"--estimator={estimator}"]
        if estimator != "gae":
          flags.append("--rho=0.4")
        result = subprocess.run(
            [VANTAGE, "train", "--mode=local", "--env=InvertedPendulum",
             f"--steps={STEPS}", f"--horizon={HORIZON}", f"--seed={seed}",
             f"--run_dir={run_dir}"] + flags,
            capture_output=True, text=True, timeout=300)
        if result.returncode != 0:
          shutil.rmtree(cls.root, ignore_errors=True)
          raise RuntimeError(f"vantage train failed ({result.returncode}): "
                             f"{result.stderr[-2000:]}")
        cls.runs.append(run_dir)
    cls.out_dir = os.path.join(cls.root, "out")
    os.makedirs(cls.out_dir)

  @classmethod
  def tearDownClass(cls):
    shutil.rmtree(cls.root, ignore_errors=True)

  def out(self, name):
    return os.path.join(self.out_dir, name)

  def assertPlots(self, *args):
    """Runs a plot that must succeed; returns (groups, panels, runs)."""
    result = plot(*args)
    self.assertEqual(result.returncode, 0, result.stderr)
    self.assertEqual(result.stderr, "")
    lines = result.stdout.splitlines()
    self.assertEqual(len(lines), 1, result.stdout)
    match = re.fullmatch(
        r"wrote (.+): (\d+) groups?, (\d+) panels?, (\d+) runs?", lines[0])
    self.assertIsNotNone(match, lines[0])
    self.assertTrue(os.path.isfile(match.group(1)), match.group(1))
    return tuple(int(match.group(i)) for i in (2, 3, 4))

  def assertUsageError(self, args, *named):
    """A plot that must fail with one stderr line naming `named`, exit 2."""
    result = plot(*args)
    self.assertEqual(result.returncode, 2, result.stderr)
    self.assertEqual(result.stdout, "")
    self.assertNotIn("Traceback", result.stderr)
    lines = result.stderr.splitlines()
    self.assertEqual(len(lines), 1, result.stderr)
    self.assertTrue(lines[0].startswith("vantage plot: "), lines[0])
    for text in named:
      self.assertIn(str(text), lines[0])
    return lines[0]

  def copy_run(self, name, source=None):
    copy = os.path.join(self.root, name)
    shutil.copytree(source or self.runs[0], copy)
    self.addCleanup(shutil.rmtree, copy, ignore_errors=True)
    return copy

  # ---------------------------------------------------------------- figures

  def test_two_groups_of_two_seeds_in_the_requested_size(self):
    out = self.out("default.png")
    groups, panels, runs = self.assertPlots(*self.runs, f"--out={out}",
                                            "--width=900", "--height=600")
    self.assertEqual((groups, panels, runs), (2, 1, 4))
    image = read_png(out)
    self.assertEqual(image.shape[:2], (600, 900))
    import numpy as np
    rgb = np.round(image[:, :, :3] * 255).astype(np.uint8).reshape(-1, 3)
    self.assertGreater(len(np.unique(rgb, axis=0)), 100)
    background = (rgb == 255).all(axis=1).mean()
    self.assertLess(background, 0.99)
    # One colour per group: the first two of the cycle, not the third.
    self.assertGreater(pixels_near(image, C0), 100)
    self.assertGreater(pixels_near(image, C1), 100)
    self.assertLess(pixels_near(image, C2), 5)

  def test_default_size_is_1200_by_800(self):
    out = self.out("size.png")
    self.assertPlots(*self.runs, f"--out={out}")
    self.assertEqual(read_png(out).shape[:2], (800, 1200))

  def test_flags_as_separate_words(self):
    out = self.out("words.png")
    self.assertEqual(
        self.assertPlots(*self.runs, "--out", out, "--y", "entropy",
                         "--width", "640", "--height", "480"), (2, 1, 4))
    self.assertEqual(read_png(out).shape[:2], (480, 640))

  def test_flagfile(self):
    flagfile = self.out("flags.txt")
    with open(flagfile, "w") as f:
      f.write("--group_by=seed\n--band=minmax\n")
    self.assertEqual(
        self.assertPlots(*self.runs, f"--flagfile={flagfile}",
                         f"--out={self.out('flagfile.png')}"), (2, 1, 4))

  def test_panel_by_env_with_one_env_is_one_panel(self):
    self.assertEqual(
        self.assertPlots(*self.runs, "--panel_by=env",
                         f"--out={self.out('panel.png')}"), (2, 1, 4))

  def test_grouping_by_seed_gives_one_group_per_run(self):
    out = self.out("seed.png")
    self.assertEqual(
        self.assertPlots(*self.runs, "--group_by=estimator,seed",
                         f"--out={out}"), (4, 1, 4))
    image = read_png(out)
    for colour in (C0, C1, C2, C3):
      self.assertGreater(pixels_near(image, colour), 50, colour)
    self.assertEqual(
        self.assertPlots(*self.runs, "--group_by=seed",
                         f"--out={self.out('seed2.png')}")[0], 2)

  def test_value_loss(self):
    self.assertEqual(
        self.assertPlots(*self.runs, "--y=value_loss", "--x=updates",
                         f"--out={self.out('value_loss.png')}"), (2, 1, 4))

  def test_minmax_band(self):
    self.assertEqual(
        self.assertPlots(*self.runs, "--band=minmax", "--title=Min-max",
                         f"--out={self.out('minmax.png')}"), (2, 1, 4))

  def test_a_parent_directory_finds_all_runs(self):
    self.assertEqual(
        self.assertPlots(self.root, f"--out={self.out('parent.png')}"),
        (2, 1, 4))
    # Naming a run twice (itself and through its parent) counts it once.
    self.assertEqual(
        self.assertPlots(self.experiment, self.runs[0],
                         f"--out={self.out('twice.png')}"), (2, 1, 4))

  @unittest.skipIf(os.environ.get("VANTAGE_PLOT_VIA_SCRIPT"),
                   "vantage resolves the configs; the script alone cannot")
  def test_a_setting_older_runs_did_not_record_takes_its_default(self):
    # An older run's config.json lacks a setting added later; it ran with
    # the behaviour the setting's default (normalised observations) keeps,
    # so it belongs with newer runs that record the default.
    root = tempfile.mkdtemp(prefix="plot_old_runs.")
    self.addCleanup(shutil.rmtree, root, ignore_errors=True)
    runs = {}
    for name, value in [("recorded", True), ("older", None), ("off", False)]:
      runs[name] = os.path.join(root, name)
      shutil.copytree(self.runs[0], runs[name])
      path = os.path.join(runs[name], "config.json")
      with open(path) as f:
        config = json.load(f)
      self.assertIs(config["training"]["normalize_observations"], True)
      if value is None:
        del config["training"]["normalize_observations"]
      else:
        config["training"]["normalize_observations"] = value
      with open(path, "w") as f:
        json.dump(config, f)
    self.assertEqual(
        self.assertPlots(runs["recorded"], runs["older"],
                         f"--out={self.out('older.png')}"), (1, 1, 2))
    self.assertEqual(
        self.assertPlots(root, f"--out={self.out('older_and_off.png')}"),
        (2, 1, 3))
    # The flat config.json of still older runs: vantage converts it.
    flat = os.path.join(root, "flat", "run")
    os.makedirs(flat)
    shutil.copy(os.path.join(self.runs[0], "progress.csv"), flat)
    with open(os.path.join(flat, "config.json"), "w") as f:
      json.dump({"mode": "local", "env": "InvertedPendulum",
                 "estimator": "gae", "steps": STEPS, "horizon": HORIZON}, f)
    self.assertEqual(
        self.assertPlots(flat, f"--out={self.out('flat.png')}"), (1, 1, 1))

  def test_panel_by_env_with_two_envs(self):
    other = self.copy_run("other-env")
    self.set_env(other, "HalfCheetah")
    self.assertEqual(
        self.assertPlots(*self.runs, other, "--panel_by=env",
                         f"--out={self.out('two_envs.png')}"), (2, 2, 5))

  def test_pdf(self):
    out = self.out("figure.pdf")
    self.assertPlots(*self.runs, f"--out={out}")
    with open(out, "rb") as f:
      self.assertEqual(f.read(5), b"%PDF-")

  def test_help(self):
    result = plot("--help")
    self.assertEqual(result.returncode, 0, result.stderr)
    self.assertTrue(result.stdout.startswith("usage: vantage plot"))
    for flag in ("--out", "--x=env_steps", "--y=mean_return", "--group_by",
                 "--panel_by", "--band=sd", "--title", "--width=1200",
                 "--height=800"):
      self.assertIn(flag, result.stdout)

  # ----------------------------------------------------------------- errors

  def set_env(self, run_dir, env):
    path = os.path.join(run_dir, "config.json")
    with open(path) as f:
      config = json.load(f)
    config["training"]["env"] = env
    with open(path, "w") as f:
      json.dump(config, f)

  def test_missing_directory(self):
    missing = os.path.join(self.root, "no-such-run")
    self.assertUsageError([missing, f"--out={self.out('x.png')}"], missing)

  def test_run_without_progress(self):
    broken = self.copy_run("no-progress")
    os.remove(os.path.join(broken, "progress.csv"))
    self.assertUsageError([broken, f"--out={self.out('x.png')}"], broken,
                          "progress.csv")
    # Found below a parent directory, it is named too.
    self.assertUsageError([self.root, f"--out={self.out('x.png')}"], broken,
                          "progress.csv")

  def test_progress_without_rows(self):
    empty = self.copy_run("no-rows")
    path = os.path.join(empty, "progress.csv")
    with open(path) as f:
      header = f.readline()
    with open(path, "w") as f:
      f.write(header)
    self.assertUsageError([empty, f"--out={self.out('x.png')}"], path,
                          "no rows")

  def test_unknown_column(self):
    self.assertUsageError([*self.runs, "--y=no_such_column",
                           f"--out={self.out('x.png')}"],
                          "no_such_column", "mean_return", "value_loss")
    self.assertUsageError([*self.runs, "--x=steps_taken",
                           f"--out={self.out('x.png')}"],
                          "steps_taken", "env_steps")

  def test_unknown_field(self):
    self.assertUsageError([*self.runs, "--group_by=estimator,colour",
                           f"--out={self.out('x.png')}"], "colour", "rho")
    self.assertUsageError([*self.runs, "--panel_by=planet",
                           f"--out={self.out('x.png')}"], "planet")

  def test_different_envs_need_panel_by(self):
    other = self.copy_run("other-env")
    self.set_env(other, "HalfCheetah")
    self.assertUsageError([*self.runs, other, f"--out={self.out('x.png')}"],
                          "HalfCheetah", "InvertedPendulum",
                          "--panel_by=env")

  def test_no_runs_found(self):
    empty = os.path.join(self.root, "empty")
    os.makedirs(os.path.join(empty, "nothing", "here"))
    self.addCleanup(shutil.rmtree, empty, ignore_errors=True)
    self.assertUsageError([empty, f"--out={self.out('x.png')}"], empty,
                          "no runs")

  def test_bad_flags(self):
    self.assertUsageError([*self.runs, "--band=iqr",
                           f"--out={self.out('x.png')}"], "--band")
    self.assertUsageError([*self.runs, "--no_such_flag=1",
                           f"--out={self.out('x.png')}"], "--no_such_flag")
    self.assertUsageError([*self.runs], "--out")
    missing_parent = os.path.join(self.root, "no-such-dir", "x.png")
    self.assertUsageError([*self.runs, f"--out={missing_parent}"],
                          os.path.dirname(missing_parent))


class LegendTest(unittest.TestCase):
  """Legend labels, on the script's own objects (no runs needed)."""

  @classmethod
  def setUpClass(cls):
    sys.path.insert(0, os.path.dirname(SCRIPT))
    import plot_runs
    cls.module = plot_runs

  def group(self, **fields):
    base = {"advantage.estimator": "gae", "advantage.rho": 0.5}
    base.update(fields)
    group = self.module.Group(())
    group.runs.append(self.module.Run("dir", base, [], []))
    return group

  def test_a_section_absent_from_some_groups_is_named_once(self):
    na = self.module.NA
    groups = [
        self.group(**{"exploration.ex2.hidden": na,
                      "exploration.ex2.kl_weight": na}),
        self.group(**{"exploration.ex2.hidden": (16, 16),
                      "exploration.ex2.kl_weight": 0.01}),
        self.group(**{"advantage.estimator": "max",
                      "exploration.ex2.hidden": (16, 16),
                      "exploration.ex2.kl_weight": 0.01}),
    ]
    self.module._label_groups(
        groups, [], ["advantage.estimator", "exploration.ex2.hidden",
                     "exploration.ex2.kl_weight"], explicit=False)
    self.assertEqual([g.label for g in groups],
                     ["gae no ex2", "gae ex2", "max ex2"])

  def test_values_that_differ_among_present_sections_stay(self):
    na = self.module.NA
    groups = [self.group(**{"exploration.ex2.kl_weight": na}),
              self.group(**{"exploration.ex2.kl_weight": 0.01}),
              self.group(**{"exploration.ex2.kl_weight": 0.1})]
    self.module._label_groups(groups, [], ["exploration.ex2.kl_weight"],
                              explicit=False)
    self.assertEqual([g.label for g in groups],
                     ["kl_weight=n/a", "kl_weight=0.01", "kl_weight=0.1"])


if __name__ == "__main__":
  path = take_vantage_flag(sys.argv)
  if path:
    VANTAGE = os.path.abspath(path)
  if not os.access(VANTAGE, os.X_OK):
    sys.exit(f"plot_runs_test: no vantage binary at {VANTAGE} "
             f"(pass --vantage=PATH)")
  unittest.main()
