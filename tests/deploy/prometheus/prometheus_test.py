#!/usr/bin/python3
"""The shipped Prometheus configuration, alerts and Grafana dashboard against
a real Prometheus server scraping a live `vantage train --metrics` run.

  /usr/bin/python3 tests/deploy/prometheus/prometheus_test.py --vantage=build/vantage

Starts the run (2 actors) and deploy/prometheus/watch_runs.sh (Debian's
prometheus, from deploy/setup.sh) on loopback ports with temporary storage,
then evaluates every PromQL expression of the dashboard and of the alert
rules through Prometheus's HTTP API, compares the scraped counters with
progress.csv, and kills the whole run to see the learner-down alert fire.
"""

import json
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.parse
import urllib.request

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
PROMETHEUS_DIR = os.path.join(REPO, "deploy", "prometheus")
DASHBOARD = os.path.join(REPO, "deploy", "grafana", "dashboards",
                         "vantage.json")
VANTAGE = os.path.join(REPO, "build", "vantage")


def take_vantage_flag(argv):
  rest = []
  path = None
  for arg in argv:
    if arg.startswith("--vantage="):
      path = arg.split("=", 1)[1]
    else:
      rest.append(arg)
  return path, rest


def free_port():
  with socket.socket() as s:
    s.bind(("127.0.0.1", 0))
    return s.getsockname()[1]


def wait_for(what, predicate, timeout):
  deadline = time.time() + timeout
  while time.time() < deadline:
    value = predicate()
    if value:
      return value
    time.sleep(1)
  raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def read_progress(path):
  with open(path) as f:
    lines = [line.strip().split(",") for line in f if line.strip()]
  header = lines[0]
  return [dict(zip(header, row)) for row in lines[1:] if len(row) == len(header)]


class PrometheusTest(unittest.TestCase):

  @classmethod
  def setUpClass(cls):
    cls.tmp = tempfile.mkdtemp(prefix="vantage_prometheus_test_")
    runs = os.path.join(cls.tmp, "runs")
    # Nested like an experiment's cells: the watcher finds it at any depth.
    cls.run_dir = os.path.join(runs, "InvertedPendulum", "seed-0")
    os.makedirs(os.path.dirname(cls.run_dir))
    cls.train_log = open(os.path.join(cls.tmp, "train.log"), "w")
    cls.train = subprocess.Popen(
        [VANTAGE, "train", "--actors=2", "--horizon=512", "--steps=100000000",
         "--metrics=0", "--checkpoint_every=1000", "--run_dir=" + cls.run_dir,
         # EX2 fits from the second update on, for its panels.
         "--exploration=ex2", "--ex2_replay_min=1024",
         "--ex2_first_train_iterations=50", "--ex2_train_iterations=20",
         # Evaluations from the second update on, for theirs.
         "--eval_every=2", "--eval_episodes=2"],
        stdout=cls.train_log, stderr=subprocess.STDOUT, start_new_session=True)
    cls.listen = f"127.0.0.1:{free_port()}"
    cls.state = os.path.join(cls.tmp, "prometheus")
    cls.watch_log = open(os.path.join(cls.tmp, "watch.log"), "w")
    cls.watch = subprocess.Popen(
        [os.path.join(PROMETHEUS_DIR, "watch_runs.sh"), runs, "--listen",
         cls.listen, "--state", cls.state],
        stdout=cls.watch_log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
      wait_for("Prometheus to answer", cls.ready, 60)
      wait_for("3 targets (a learner, 2 actors) up", cls.targets_up, 120)
      # Enough scrapes for rate() over a minute, and a few updates.
      wait_for("4 updates scraped", lambda: cls.scalar(
          f'vantage_learner_policy_version{{run="{cls.run_dir}"}}') >= 4, 60)
      wait_for("an evaluation scraped", lambda: cls.scalar(
          f'vantage_learner_eval_policy_version{{run="{cls.run_dir}"}}') >= 2,
               120)
      time.sleep(12)
    except Exception:
      cls.tearDownClass()
      raise

  @classmethod
  def tearDownClass(cls):
    for process in (cls.train, cls.watch):
      if process.poll() is None:
        try:
          os.killpg(process.pid, signal.SIGTERM)
          process.wait(timeout=30)
        except (ProcessLookupError, subprocess.TimeoutExpired):
          os.killpg(process.pid, signal.SIGKILL)
          process.wait()
    cls.train_log.close()
    cls.watch_log.close()
    if os.environ.get("VANTAGE_KEEP_TEST_DIRS"):
      print("kept", cls.tmp, file=sys.stderr)
    else:
      shutil.rmtree(cls.tmp, ignore_errors=True)

  # --- Prometheus's HTTP API ---
  @classmethod
  def api(cls, path, **params):
    url = f"http://{cls.listen}/api/v1/{path}"
    if params:
      url += "?" + urllib.parse.urlencode(params, doseq=True)
    with urllib.request.urlopen(url, timeout=10) as response:
      body = json.load(response)
    if body.get("status") != "success":
      raise AssertionError(f"{path} {params}: {body}")
    return body["data"]

  @classmethod
  def ready(cls):
    try:
      with urllib.request.urlopen(f"http://{cls.listen}/-/ready", timeout=2):
        return True
    except OSError:
      return False

  @classmethod
  def targets_up(cls):
    active = cls.api("targets")["activeTargets"]
    return len([t for t in active if t["health"] == "up"]) == 3

  @classmethod
  def query(cls, expr, at=None):
    params = {"query": expr}
    if at is not None:
      params["time"] = at
    return cls.api("query", **params)["result"]

  @classmethod
  def scalar(cls, expr, at=None):
    result = cls.query(expr, at)
    return float(result[0]["value"][1]) if result else -1

  def substitute(self, expr):
    return (expr.replace("$run", self.run_dir)
            .replace("$__rate_interval", "1m"))

  # --- the tests, in name order ---
  def test_1_shipped_files_pass_promtool(self):
    for args in (["check", "config", os.path.join(self.state, "prometheus.yml")],
                 ["check", "rules", os.path.join(PROMETHEUS_DIR, "alerts.yml")]):
      result = subprocess.run(["promtool"] + args, capture_output=True,
                              text=True)
      self.assertEqual(result.returncode, 0, result.stdout + result.stderr)

  def test_1_targets_carry_the_runs_labels(self):
    active = self.api("targets")["activeTargets"]
    roles = sorted(t["labels"]["role"] for t in active)
    self.assertEqual(roles, ["actor", "actor", "learner"])
    for target in active:
      labels = target["labels"]
      self.assertEqual(labels["run"], self.run_dir)
      self.assertEqual(labels["env"], "InvertedPendulum")
      self.assertEqual(labels["algo"], "ppo")
      self.assertIn("estimator", labels)
    self.assertEqual(sorted(t["labels"].get("actor", "") for t in active),
                     ["", "0", "1"])

  def test_2_every_dashboard_query_returns_data(self):
    with open(DASHBOARD) as f:
      dashboard = json.load(f)
    variables = {v["name"]: v for v in dashboard["templating"]["list"]}
    self.assertIn("run", variables)
    # The run selector's label_values(metric, run).
    runs = self.api("label/run/values",
                    **{"match[]": "vantage_learner_policy_version"})
    self.assertIn(self.run_dir, runs)
    expressions = [(panel["title"], target["expr"])
                   for panel in dashboard["panels"]
                   for target in panel["targets"]]
    self.assertGreaterEqual(len(dashboard["panels"]), 16)
    empty = [f"{title}: {expr}" for title, expr in expressions
             if not self.query(self.substitute(expr))]
    self.assertEqual(empty, [], "dashboard queries without data")

  def test_3_scraped_counters_agree_with_progress_csv(self):
    run = f'run="{self.run_dir}"'
    names = {"version": "vantage_learner_policy_version",
             "env_steps": "vantage_learner_env_steps_total",
             "episodes": "vantage_learner_episodes_total",
             "mean_return": "vantage_learner_mean_return",
             "elapsed": "vantage_learner_run_elapsed_seconds"}
    # The values of one scrape; an update can fall between two of the
    # learner's reports, so a mismatch is retried at a later scrape.
    mismatch = None
    for _ in range(5):
      at = time.time()
      values = {k: self.scalar(f"{m}{{{run}}}", at) for k, m in names.items()}
      rows = {int(r["updates"]): r for r in read_progress(
          os.path.join(self.run_dir, "progress.csv"))}
      row = rows.get(int(values["version"]))
      if row is None:
        mismatch = f"no progress row for version {values['version']}"
      elif (int(row["env_steps"]) != values["env_steps"] or
            int(row["episodes"]) != values["episodes"] or
            not math.isclose(float(row["mean_return"]), values["mean_return"],
                             rel_tol=1e-6) or
            not math.isclose(float(row["elapsed_s"]), values["elapsed"],
                             abs_tol=1e-3)):
        mismatch = f"{values} vs {row}"
      else:
        self.assertGreater(values["env_steps"], 0)
        return
      time.sleep(6)
    self.fail(mismatch)

  def test_4_every_alert_rule_is_valid_and_evaluates(self):
    with open(os.path.join(PROMETHEUS_DIR, "alerts.yml")) as f:
      text = f.read()
    groups = wait_for("every rule evaluated", lambda: (
        [g for g in self.api("rules")["groups"]
         if all(r["health"] == "ok" for r in g["rules"])] or None), 60)
    rules = {r["name"]: r for g in groups for r in g["rules"]}
    for name in ("VantageLearnerDown", "VantageNoUpdate",
                 "VantageRejectedSegments", "VantagePolicyLagAboveLimit",
                 "VantageActorGone", "VantageNoLiveActors",
                 "VantageActorStalled"):
      self.assertIn(name, rules)
      self.assertIn(name, text)
      self.query(rules[name]["query"])  # raises unless it evaluates
    # A healthy run raises none.
    self.assertEqual([a for a in self.api("alerts")["alerts"]
                      if a["labels"].get("run") == self.run_dir], [])

  def test_5_learner_down_fires_when_the_run_is_killed(self):
    # The whole run dies at once, as with a lost node: the launcher cannot
    # clear the scrape targets, so Prometheus sees the learner down.
    os.killpg(self.train.pid, signal.SIGKILL)
    self.train.wait()

    def firing():
      return [a for a in self.api("alerts")["alerts"]
              if a["labels"]["alertname"] == "VantageLearnerDown" and
              a["labels"].get("run") == self.run_dir and
              a["state"] == "firing"]

    alerts = wait_for("VantageLearnerDown to fire", firing, 120)
    self.assertEqual(alerts[0]["labels"]["rank"], "0")


if __name__ == "__main__":
  path, rest = take_vantage_flag(sys.argv)
  if path:
    VANTAGE = os.path.abspath(path)
  unittest.main(argv=rest, verbosity=2)
