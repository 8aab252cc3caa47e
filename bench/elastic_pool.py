#!/usr/bin/env python3
"""The elastic actor pool, measured: one `vantage learner` (sync, a batch of
`--envs` rollouts) and actors of one env each started and killed on this
machine. Phases of `--phase_s` seconds each:

  full      the run's planned actors
  half      half of them killed (SIGKILL: their calls end at once)
  back      the killed ones started again
  more      as many again added (twice the plan)

For each phase: env steps consumed per second (from progress.csv, after
`--settle_s` seconds of the phase, so that joining actors and the learner's
5 s raise grace are past), its ratio to `full`, and the rollouts dropped as
stale. Ratios within one run on one machine; absolute rates are not
comparable across machines.

  python3 bench/elastic_pool.py --vantage=build/vantage [--actors=4]
"""

import argparse
import csv
import os
import signal
import subprocess
import sys
import tempfile
import time


def start(vantage, args, log):
    return subprocess.Popen([vantage] + args, stdout=log, stderr=log)


def rows(run_dir):
    path = os.path.join(run_dir, "progress.csv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def rate(run_dir, start_s, end_s):
    """Steps per second between the first and last update in the window."""
    inside = [r for r in rows(run_dir)
              if start_s <= float(r["elapsed_s"]) <= end_s]
    if len(inside) < 2:
        return 0.0, 0
    first, last = inside[0], inside[-1]
    steps = int(last["env_steps"]) - int(first["env_steps"])
    seconds = float(last["elapsed_s"]) - float(first["elapsed_s"])
    return steps / seconds, int(last["rejected_segments"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--vantage", default="build/vantage")
    parser.add_argument("--env", default="InvertedPendulum")
    parser.add_argument("--actors", type=int, default=4)
    parser.add_argument("--horizon", type=int, default=256)
    parser.add_argument("--phase_s", type=float, default=25)
    parser.add_argument("--settle_s", type=float, default=8)
    flags = parser.parse_args()
    work = tempfile.mkdtemp(prefix="vantage-elastic-")
    run_dir = os.path.join(work, "run")
    port_file = os.path.join(work, "port")
    log = open(os.path.join(work, "log"), "w")
    learner = start(flags.vantage, [
        "learner", f"--env={flags.env}", f"--envs={flags.actors}",
        f"--horizon={flags.horizon}", "--steps=100000000", "--seed=1",
        f"--run_dir={run_dir}", f"--port_file={port_file}"], log)
    while not os.path.exists(port_file) or not open(port_file).read().strip():
        time.sleep(0.1)
    address = "127.0.0.1:" + open(port_file).read().strip()
    actor_args = ["actor", f"--learner={address}", f"--env={flags.env}",
                  "--envs=1"]
    actors = [start(flags.vantage, actor_args, log) for _ in range(flags.actors)]
    t0 = time.time()
    while not rows(run_dir):
        time.sleep(0.1)
    clock = lambda: time.time() - t0
    phases = []

    def phase(name, change):
        change()
        begin = clock()
        time.sleep(flags.phase_s)
        phases.append((name, begin + flags.settle_s, clock()))

    half = flags.actors // 2
    phase("full", lambda: None)

    def kill_half():
        for a in actors[:half]:
            a.send_signal(signal.SIGKILL)
            a.wait()
    phase("half", kill_half)

    def restart_half():
        for i in range(half):
            actors[i] = start(flags.vantage, actor_args, log)
    phase("back", restart_half)
    phase("more", lambda: actors.extend(
        start(flags.vantage, actor_args, log) for _ in range(flags.actors)))
    for a in actors:
        a.send_signal(signal.SIGTERM)
    learner.send_signal(signal.SIGTERM)
    for p in actors + [learner]:
        p.wait()
    # progress.csv's elapsed_s counts from the learner's start; the phases
    # from the first update: align them by the first row.
    offset = float(rows(run_dir)[0]["elapsed_s"])
    full = None
    print(f"elastic pool: {flags.env}, sync, batch {flags.actors} x "
          f"{flags.horizon} steps, actors of 1 env, {os.cpu_count()} cores")
    for name, begin, end in phases:
        steps_per_s, stale = rate(run_dir, begin + offset, end + offset)
        full = full or steps_per_s
        print(f"  {name:5s} {steps_per_s:9.0f} steps/s  "
              f"{steps_per_s / full:5.2f}x full  rejected so far {stale}")
    print(f"(run directory and logs in {work})")


if __name__ == "__main__":
    sys.exit(main())
