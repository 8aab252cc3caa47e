#!/usr/bin/env python3
"""deploy/slurm/ against a real Slurm: munged, slurmctld and slurmd started
here by deploy/slurm/local_cluster.sh (this machine the only node) and
stopped at the end, whatever happens. (1) train.sbatch trains InvertedPendulum
with a learner and two actor tasks to completion, listing their metrics
endpoints in the run's scrape targets; (2) a job that gets TERM
mid-run checkpoints, is requeued and resumes to completion; (3) a 2x2
experiment runs as a job array and its report counts every run."""

import argparse
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
CLUSTER = os.path.join(REPO, "deploy", "slurm", "local_cluster.sh")
SBATCH_SCRIPT = os.path.join(REPO, "deploy", "slurm", "train.sbatch")
FAILURES = []


def check(condition, message):
    if condition:
        print(f"ok: {message}")
    else:
        print(f"FAILED: {message}")
        FAILURES.append(message)
    return condition


def run(args, **kwargs):
    return subprocess.run(args, capture_output=True, text=True, **kwargs)


def job_fields(job):
    out = run(["scontrol", "show", "job", job]).stdout
    return dict(re.findall(r"(\w+)=(\S*)", out))


def wait_for_job(job, seconds):
    deadline = time.time() + seconds
    while time.time() < deadline:
        fields = job_fields(job)
        if fields.get("JobState") in ("COMPLETED", "FAILED", "CANCELLED",
                                      "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY"):
            return fields
        time.sleep(1)
    raise RuntimeError(f"job {job} did not end within {seconds} s: "
                       f"{job_fields(job)}")


def progress(run_dir):
    """(env_steps, policy_version) of every row of progress.csv."""
    with open(os.path.join(run_dir, "progress.csv")) as f:
        header = f.readline().strip().split(",")
        steps, version = header.index("env_steps"), header.index(
            "policy_version")
        rows = [line.strip().split(",") for line in f if line.strip()]
    return [(int(r[steps]), int(r[version])) for r in rows]


def check_rows(rows, steps, what):
    versions = [v for _, v in rows]
    check(versions == list(range(1, len(rows) + 1)),
          f"{what}: one progress row per policy version, in order "
          f"(versions {versions})")
    check(rows and rows[-1][0] == steps,
          f"{what}: the last row is at {steps} steps ({rows[-1:]})")


def submit(vantage, work, run_dir, train_args, metrics=False):
    env = dict(os.environ, VANTAGE_BIN=vantage, VANTAGE_RUN_DIR=run_dir,
               VANTAGE_TRAIN_ARGS=train_args,
               VANTAGE_METRICS="1" if metrics else "0")
    # --overcommit: three tasks on a node of two CPUs (the learner waits
    # while the actors step).
    out = run(["sbatch", "--parsable", "--overcommit", "--ntasks=3",
               f"--chdir={work}", SBATCH_SCRIPT], env=env)
    if out.returncode != 0:
        raise RuntimeError(f"sbatch failed: {out.stderr.strip()}")
    return out.stdout.strip().split(";")[0]


def one_run(vantage, work):
    run_dir = os.path.join(work, "runs", "one")
    job = submit(vantage, work, run_dir, "--steps=40960", metrics=True)
    # The scrape targets while it runs: the learner and both actors.
    targets_path = os.path.join(run_dir, "prometheus_targets.json")
    roles = []
    deadline = time.time() + 120
    while time.time() < deadline and not roles:
        try:
            with open(targets_path) as f:
                roles = sorted(t["labels"]["role"] for t in json.load(f))
        except (OSError, ValueError):
            pass
        time.sleep(0.2)
    check(roles == ["actor", "actor", "learner"],
          f"prometheus_targets.json lists the learner and two actors "
          f"while the job runs ({roles})")
    fields = wait_for_job(job, 300)
    log = open(os.path.join(work, f"vantage-{job}.out")).read()
    check(fields.get("JobState") == "COMPLETED" and
          fields.get("ExitCode") == "0:0",
          f"train.sbatch job {job} completed with exit 0 "
          f"({fields.get('JobState')}, {fields.get('ExitCode')})")
    check("starting 2 actors on InvertedPendulum" in log,
          "the job started two actor tasks")
    check("RESULT train env=InvertedPendulum" in log,
          "the learner printed its RESULT line")
    check_rows(progress(run_dir), 40960, "one run")
    with open(targets_path) as f:
        check(json.load(f) == [], "the finished job emptied its targets")
    # The same job again on the finished run: it ends at once, untouched.
    again = submit(vantage, work, run_dir, "--steps=40960")
    fields = wait_for_job(again, 120)
    log = open(os.path.join(work, f"vantage-{again}.out")).read()
    check(fields.get("JobState") == "COMPLETED" and
          "is finished already (40960 steps)" in log,
          "a job on the finished run completes without training")
    check(len(progress(run_dir)) == 10, "and leaves its progress as it was")
    mode = stat.S_IMODE(os.stat(os.path.join(run_dir, "slurm",
                                             "token")).st_mode)
    check(mode == 0o600, f"the job's auth token is mode 0600 ({oct(mode)})")


def requeued_run(vantage, work):
    run_dir = os.path.join(work, "runs", "requeued")
    job = submit(vantage, work, run_dir,
                 "--steps=40960 --checkpoint_every=1")
    checkpoints = os.path.join(run_dir, "checkpoints")
    deadline = time.time() + 180
    while time.time() < deadline:
        if os.path.isdir(checkpoints) and len(os.listdir(checkpoints)) >= 2:
            break
        time.sleep(0.2)
    signalled = run(["scancel", "--signal=TERM", "--batch", job])
    check(signalled.returncode == 0,
          f"scancel --signal=TERM --batch {job} {signalled.stderr.strip()}")
    fields = wait_for_job(job, 400)
    log = open(os.path.join(work, f"vantage-{job}.out")).read()
    check(fields.get("Restarts") == "1",
          f"the signalled job was requeued once (Restarts={fields.get('Restarts')})")
    check(fields.get("JobState") == "COMPLETED",
          f"the requeued job completed ({fields.get('JobState')})")
    stopped = re.search(r"learner stopped \(exit (\d+)\)", log)
    check(stopped and stopped.group(1) == "0",
          "the TERMed learner exited 0 (it checkpointed its last update)")
    resumed = re.search(r"resuming \S+ from policy version (\d+)", log)
    check(resumed is not None and int(resumed.group(1)) >= 2,
          f"the requeued job resumed from its checkpoint "
          f"({resumed.group(0) if resumed else 'no resume line'})")
    check_rows(progress(run_dir), 40960, "requeued run")


EXPERIMENT = """{
  "name": "slurm-grid",
  "base": {"mode": "local",
           "training": {"env": "InvertedPendulum", "steps": "8192",
                        "horizon": "512"},
           "ppo": {"epochs": 4, "minibatches": 4},
           "recording": {"checkpoint_every": 4}},
  "seeds": [0, 1],
  "variants": [{"set": {"estimator": "max"}}, {"set": {"estimator": "gae"}}]
}"""


def job_array(vantage, work):
    path = os.path.join(work, "grid.json")
    with open(path, "w") as f:
        f.write(EXPERIMENT)
    exp_dir = os.path.join(work, "grid")
    ran = run([vantage, "experiment", "run", path, f"--out={exp_dir}",
               "--backend=slurm", "--jobs=2"], timeout=600)
    print(ran.stdout)
    check(ran.returncode == 0,
          f"experiment run --backend=slurm exit 0 ({ran.stderr.strip()})")
    check(re.search(r"job array \d+ \(4 tasks\)", ran.stdout) is not None,
          "the grid went to Slurm as one job array of 4 tasks")
    outputs = [n for n in os.listdir(os.path.join(exp_dir, "slurm"))
               if n.startswith("array-")]
    check(len(outputs) == 4, f"four array task outputs ({outputs})")
    for cell in ("max-rho0.4-E1-16-64-2048/seed-0",
                 "max-rho0.4-E1-16-64-2048/seed-1", "gae/seed-0",
                 "gae/seed-1"):
        rows = progress(os.path.join(exp_dir, "InvertedPendulum", cell))
        check(rows and rows[-1][0] == 8192, f"{cell} ran to 8192 steps")
    again = run([vantage, "experiment", "run", path, f"--out={exp_dir}",
                 "--backend=slurm"], timeout=120)
    check(again.returncode == 0 and "4 finished, 0 to resume, 0 to start"
          in again.stdout, "running the grid again submits nothing")
    report = run([vantage, "experiment", "report", exp_dir, "--no_figures"],
                 timeout=300)
    check(report.returncode == 0 and
          "1 envs, 2 groups, 4 finished runs" in report.stdout,
          f"the report counts the four runs ({report.stdout.strip()} "
          f"{report.stderr.strip()})")


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--vantage", required=True)
    args = parser.parse_args()
    vantage = os.path.abspath(args.vantage)
    work = tempfile.mkdtemp(prefix="vantage-slurm-")
    cluster = os.path.join(work, "cluster")
    os.environ["SLURM_CONF"] = os.path.join(cluster, "slurm.conf")
    try:
        started = run([CLUSTER, "start", cluster], timeout=120)
        print(started.stdout + started.stderr)
        if started.returncode != 0:
            print("FAILED: the local Slurm did not start")
            return 1
        one_run(vantage, work)
        requeued_run(vantage, work)
        job_array(vantage, work)
    finally:
        stopped = run([CLUSTER, "stop", cluster], timeout=120)
        print(stopped.stdout + stopped.stderr)
        left = run(["pgrep", "-af", work]).stdout.strip()
        check(left == "", f"no daemon or job of the test is left ({left})")
        shutil.rmtree(work, ignore_errors=True)
    if FAILURES:
        print(f"{len(FAILURES)} checks failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
