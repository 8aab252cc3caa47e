#!/usr/bin/python3
"""Runs the pods of deploy/k8s/base as processes on this machine: the
rendered learner and actor containers' args and env, with the given binary
in place of the image's ENTRYPOINT, and kills the learner mid-run.

usage: k8s_pods_as_processes_test.py --vantage=PATH_TO_BINARY
                                     [--kubectl=kubectl] [--keep]

What a kubelet would do, done here:
- env: values, ConfigMap keys and the downward API's metadata.name, and
  $(VAR) in args expanded from them;
- volumes: each ConfigMap and Secret volume written to a directory of a
  scratch root, each emptyDir a directory, the StatefulSet's claim one
  directory that outlives the learner's process (as a PVC outlives its pod);
  every absolute path in the args is rewritten to where its volume is;
- the Service vantage-learner resolves to 127.0.0.1; the containers' fixed
  ports (50051, 9100) become free ports, so the test can run beside others.

Changed from the rendering, and nothing else: run.json's training.steps
(two checkpoints' worth of updates instead of 150000 steps), and the
Secret's token, whose placeholder is empty (the pods are first shown to
refuse it) and which the test generates as docs/deploy.md tells users to.

Then: the learner pod starts and serves; `vantage health` (its probe's
command) answers SERVING, and fails against a closed port; the actor pods
start (the Deployment's replicas); both metrics endpoints answer only with
basic auth; once the learner has checkpointed and gone past the checkpoint
it is SIGKILLed and started again with the same args and claim: it must
say it resumes, the same actor processes must reconnect by themselves, and
the learner must finish (exit 0) with progress.csv holding one row per
update (the rows up to the checkpoint unchanged, none missing, none twice)
and the run's final step count. The actors, told by the finishing learner
that the run is over, then end by themselves (exit 0) within the pod's
grace period. No process is left behind.
"""

import argparse
import base64
import csv
import io
import json
import os
import re
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
import k8s_render  # noqa: E402
from k8s_render import TestFailure  # noqa: E402

LEARNER = ("StatefulSet", "vantage-learner")
# What an actor logs when the learner tells it the run is complete.
RUN_OVER = "the run is over: every step is done; exiting"
ACTOR = ("Deployment", "vantage-actor")
SERVICE = ("Service", "vantage-learner")
# Generous bounds for a loaded two-core machine; the base's run is about
# two dozen updates of ~0.5 s each here.
SERVE_TIMEOUT_S = 120
RUN_TIMEOUT_S = 900


def fail(message):
    raise TestFailure(message)


def tail(path, chars=600):
    try:
        with open(path, errors="replace") as f:
            return " | ".join(f.read()[-chars:].splitlines())
    except OSError:
        return "(no log)"


def free_port():
    # Bound on every address, as the containers bind 0.0.0.0.
    with socket.socket() as s:
        s.bind(("0.0.0.0", 0))
        return s.getsockname()[1]


def peak_rss_mb(process):
    """The process's peak resident memory (VmHWM), MiB; for the log."""
    try:
        with open(f"/proc/{process.pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return float("nan")


def port_open(port):
    with socket.socket() as s:
        s.settimeout(1)
        return s.connect_ex(("127.0.0.1", port)) == 0


# --- the pods ------------------------------------------------------------------

class Pod:
    """One pod's container as a process: its argv, env and volumes."""

    def __init__(self, objects, workload, name, root, claims, vantage, service_ports):
        self.name = name
        self.root = root
        self.workload = workload
        container = k8s_render.container(workload)
        if container.get("command"):
            fail(f"{name}: the container sets command; expected the image's ENTRYPOINT")
        # containerPort -> the free port this process uses instead.
        self.ports = {p["containerPort"]: free_port() for p in container.get("ports", [])}
        self.mounts = {}  # mountPath -> directory here
        self.writable = []
        volumes = {v["name"]: v for v in workload["spec"]["template"]["spec"].get("volumes", [])}
        for mount in container.get("volumeMounts", []):
            path = mount["mountPath"]
            if mount["name"] in volumes:
                directory = os.path.join(root, path.lstrip("/"))
                self.materialize(objects, volumes[mount["name"]], directory)
            elif mount["name"] in claims:
                directory = claims[mount["name"]]
                self.writable.append(directory)
            else:
                fail(f"{name}: volumeMount {mount['name']} names no volume")
            self.mounts[path] = directory
        env = k8s_render.container_env(objects, workload, name)
        self.args = [self.rewrite(k8s_render.expand(a, env), service_ports)
                     for a in container.get("args", [])]
        self.argv = [vantage] + self.args
        # A container's environment is the pod's, not the test's; PATH and
        # HOME are what an image would give.
        self.env = dict(env, PATH=os.environ.get("PATH", "/usr/bin:/bin"),
                        HOME=os.path.join(root, "home"))
        os.makedirs(self.env["HOME"], exist_ok=True)
        self.grace_s = workload["spec"]["template"]["spec"].get(
            "terminationGracePeriodSeconds", 30)
        self.process = None
        self.log = None

    def materialize(self, objects, volume, directory):
        os.makedirs(directory, exist_ok=True)
        if "emptyDir" in volume:
            self.writable.append(directory)
            return
        if "configMap" in volume:
            source = volume["configMap"]
            data = k8s_render.find(objects, "ConfigMap", source["name"]).get("data", {})
        elif "secret" in volume:
            source = volume["secret"]
            data = k8s_render.secret_data(k8s_render.find(objects, "Secret", source["secretName"]))
        else:
            fail(f"{self.name}: volume {volume['name']} is of a kind this test does not model")
        items = source.get("items") or [{"key": k, "path": k} for k in data]
        for item in items:
            path = os.path.join(directory, item["path"])
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w") as f:
                f.write(data[item["key"]])
            os.chmod(path, item.get("mode", source.get("defaultMode", 0o644)))

    def rewrite(self, arg, service_ports):
        """A volume's path moved to its directory here; a Service's
        HOST:PORT to 127.0.0.1 and the port behind it; one of this
        container's ports to its free port."""
        flag, equals, value = arg.partition("=")
        if not equals or not flag.startswith("--"):
            return arg
        if value.startswith("/"):
            best = max((m for m in self.mounts
                        if value == m or value.startswith(m.rstrip("/") + "/")),
                       key=len, default=None)
            if best is None:
                fail(f"{self.name}: {arg} is on no volume of the pod")
            return f"{flag}={self.mounts[best]}{value[len(best):]}"
        match = re.fullmatch(r"([A-Za-z0-9.-]+):(\d+)", value)
        if match:
            host, port = match.group(1), int(match.group(2))
            if (host, port) in service_ports:
                return f"{flag}=127.0.0.1:{service_ports[(host, port)]}"
            if port in self.ports:
                return f"{flag}={host}:{self.ports[port]}"
            fail(f"{self.name}: {arg} is neither a Service nor a port of the container")
        return arg

    def start(self, log_path):
        self.log = log_path
        with open(log_path, "w") as log:
            self.process = subprocess.Popen(
                self.argv, stdout=log, stderr=subprocess.STDOUT, env=self.env,
                cwd=self.root, preexec_fn=k8s_render.die_with_parent)
        return self.process

    def alive(self):
        return self.process is not None and self.process.poll() is None


def service_ports(objects, learner_pod):
    """(Service name, port) -> the port here of the pod behind it."""
    service = k8s_render.find(objects, *SERVICE)
    container = k8s_render.container(learner_pod.workload)
    named = {p["name"]: p["containerPort"] for p in container.get("ports", [])}
    ports = {}
    for port in service["spec"]["ports"]:
        target = port.get("targetPort", port["port"])
        target = named[target] if isinstance(target, str) else target
        ports[(service["metadata"]["name"], port["port"])] = learner_pod.ports[target]
    return ports


def shorten_run(objects):
    """Only training.steps of run.json changes: two checkpoints' worth of
    updates (checkpoint_every x 2 batches of horizon x actors x
    envs_per_actor steps). Returns (steps, batch, checkpoint_every)."""
    config_map = k8s_render.find(objects, "ConfigMap", "vantage-run")
    run = k8s_render.run_config(objects)
    batch = (int(run["training"]["horizon"]) * int(run["distributed"]["actors"]) *
             int(run["distributed"]["envs_per_actor"]))
    every = int(run["recording"]["checkpoint_every"])
    steps = batch * every * 2
    run["training"]["steps"] = str(steps)
    config_map["data"]["run.json"] = json.dumps(run, indent=1) + "\n"
    return steps, batch, every


def set_token(objects, token):
    secret = k8s_render.find(objects, "Secret", "vantage-auth")
    secret.setdefault("stringData", {})["token"] = token
    secret.get("data", {}).pop("token", None)


# --- checks --------------------------------------------------------------------

def check_binary_has_new_commands(vantage):
    learner_help = subprocess.run([vantage, "help", "learner"], capture_output=True,
                                  text=True, timeout=60).stdout
    if "--resume_if_exists" not in learner_help:
        fail(f"`{vantage} help learner` has no --resume_if_exists, which the learner "
             "pod's args use (a binary built before that flag?)")
    commands = subprocess.run([vantage, "help"], capture_output=True, text=True,
                              timeout=60).stdout
    if not re.search(r"^\s+health\s", commands, re.M):
        fail(f"`{vantage} help` lists no `health` command, which the probes run "
             "(a binary built before it?)")


def check_placeholder_refused(objects, vantage, scratch, pods):
    """With the Secret's placeholder (an empty token) both pods refuse to
    start, naming the token file."""
    token = k8s_render.secret_data(k8s_render.find(objects, "Secret", "vantage-auth"))
    if token.get("token", "") != "":
        fail("the Secret vantage-auth's placeholder token is not empty: pods would run "
             "with a token everyone knows")
    claims = {"run": os.path.join(scratch, "claim")}
    os.makedirs(claims["run"])
    learner = Pod(objects, k8s_render.find(objects, *LEARNER), "placeholder-learner",
                  os.path.join(scratch, "learner"), claims, vantage, {})
    actor = Pod(objects, k8s_render.find(objects, *ACTOR), "placeholder-actor",
                os.path.join(scratch, "actor"), {}, vantage,
                service_ports(objects, learner))
    pods.extend([learner, actor])
    for pod in (learner, actor):
        process = pod.start(os.path.join(scratch, pod.name + ".log"))
        try:
            code = process.wait(timeout=60)
        except subprocess.TimeoutExpired:
            fail(f"{pod.name} started with the empty placeholder token")
        if code == 0 or "empty" not in open(pod.log).read():
            fail(f"{pod.name} with the empty token: exit {code}, log: {tail(pod.log)}")


def scrape(port, user, token):
    """(status without credentials, status and body with user:token)."""
    url = f"http://127.0.0.1:{port}/metrics"
    try:
        urllib.request.urlopen(url, timeout=10)
        anonymous = 200
    except urllib.error.HTTPError as error:
        anonymous = error.code
    request = urllib.request.Request(url, headers={
        "Authorization": "Basic " + base64.b64encode(f"{user}:{token}".encode()).decode()})
    with urllib.request.urlopen(request, timeout=10) as response:
        return anonymous, response.status, response.read().decode(errors="replace")


def check_metrics(pod, prefix, objects):
    """The endpoint answers Prometheus' basic auth as the Secret gives it
    (keys username and token), and nobody without."""
    auth = k8s_render.secret_data(k8s_render.find(objects, "Secret", "vantage-auth"))
    port = pod.ports[9100]
    anonymous, status, body = scrape(port, auth["username"], auth["token"])
    if anonymous != 401:
        fail(f"{pod.name}: /metrics without basic auth answered {anonymous}, expected 401")
    if status != 200 or prefix not in body:
        fail(f"{pod.name}: /metrics with {auth['username']}:<token> answered {status} without "
             f"{prefix} series")


def health(vantage, port, timeout_s):
    return subprocess.run(
        [vantage, "health", f"--learner=127.0.0.1:{port}", f"--timeout_s={timeout_s}"],
        capture_output=True, text=True, timeout=timeout_s + 30)


def check_health(vantage, learner):
    result = health(vantage, learner.ports[50051], 10)
    if result.returncode != 0 or "SERVING" not in result.stdout:
        fail(f"`vantage health` on the serving learner: exit {result.returncode}, "
             f"stdout {result.stdout.strip()!r}, stderr {result.stderr.strip()[-300:]!r}")
    closed = health(vantage, free_port(), 2)
    if closed.returncode == 0:
        fail("`vantage health` against a closed port exited 0: the probe could not fail")


def read_progress(run_dir):
    path = os.path.join(run_dir, "progress.csv")
    if not os.path.exists(path):
        return [], []
    with open(path) as f:
        lines = f.read().splitlines()
    return lines[:1], lines[1:]


def newest_checkpoint(run_dir):
    names = os.listdir(os.path.join(run_dir, "checkpoints")) \
        if os.path.isdir(os.path.join(run_dir, "checkpoints")) else []
    versions = [int(m.group(1)) for m in (re.fullmatch(r"checkpoint-(\d+)\.pt", n)
                                          for n in names) if m]
    return max(versions, default=0)


def wait_until(condition, timeout_s, what, watched):
    deadline = time.monotonic() + timeout_s
    while not condition():
        for pod in watched:
            if not pod.alive():
                fail(f"{pod.name} exited ({pod.process.returncode}) while waiting for "
                     f"{what}: {tail(pod.log)}")
        if time.monotonic() > deadline:
            fail(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(0.1)


def check_progress(header, rows, kept, steps, batch, rollout, resumed_from, raised):
    """`raised`: the learner said it raised its grant (an actor registered
    more than the learner's grace after the other, as on a loaded machine):
    a sync batch then takes every rollout its live actors were granted, so
    an update may hold more than `batch` steps, whole rollouts of `rollout`
    steps each; otherwise every update holds exactly `batch`."""
    table = list(csv.DictReader(io.StringIO("\n".join(header + rows))))
    updates = [int(row["updates"]) for row in table]
    if updates != list(range(1, len(updates) + 1)):
        fail(f"progress.csv's updates are not 1..N once each: {updates}")
    env_steps = [int(row["env_steps"]) for row in table]
    if not raised:
        if env_steps != [batch * u for u in updates]:
            fail(f"progress.csv's env_steps are not {batch} per update: {env_steps}")
        if env_steps[-1] != steps:
            fail(f"progress.csv ends at {env_steps[-1]} env steps, the run has {steps}")
    else:
        sizes = [b - a for a, b in zip([0] + env_steps, env_steps)]
        if any(size < batch or size % rollout for size in sizes):
            fail(f"progress.csv's updates are not whole rollouts of {rollout} steps, "
                 f"at least {batch} each: {env_steps}")
        if env_steps[-1] < steps or (len(env_steps) > 1 and env_steps[-2] >= steps):
            fail(f"progress.csv ends at {env_steps[-1]} env steps, the run has {steps}")
    if rows[:resumed_from] != kept[:resumed_from]:
        fail(f"the rows up to the checkpoint's update {resumed_from} changed on resume")


# --- the TLS overlay -------------------------------------------------------------

def make_certificate(directory, certificate):
    """What cert-manager would put in the Certificate's Secret, from a CA
    made here with openssl: tls.crt and tls.key (ECDSA P-256, PKCS#8) for
    the Certificate's names and usages, and ca.crt."""
    if shutil.which("openssl") is None:
        fail("openssl is not on PATH (Debian's package openssl)")
    os.makedirs(directory)
    spec = certificate["spec"]
    names = [f"DNS:{n}" for n in spec.get("dnsNames", [])] + \
        [f"IP:{a}" for a in spec.get("ipAddresses", [])]
    usages = {"server auth": "serverAuth", "client auth": "clientAuth"}
    extended = [usages[u] for u in spec.get("usages", []) if u in usages]
    with open(os.path.join(directory, "extensions.cnf"), "w") as f:
        f.write(f"subjectAltName={','.join(names)}\n"
                f"extendedKeyUsage={','.join(extended)}\n"
                "keyUsage=critical,digitalSignature,keyEncipherment\n")
    ec = ["-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes"]
    commands = [
        ["openssl", "req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.crt",
         "-days", "2", "-subj", "/CN=vantage test CA"],
        ["openssl", "req", "-new", *ec, "-keyout", "tls.key", "-out", "tls.csr",
         "-subj", f"/CN={spec.get('commonName', 'vantage')}"],
        ["openssl", "x509", "-req", "-in", "tls.csr", "-CA", "ca.crt", "-CAkey",
         "ca.key", "-CAcreateserial", "-out", "tls.crt", "-days", "2",
         "-extfile", "extensions.cnf"],
    ]
    for command in commands:
        result = subprocess.run(command, cwd=directory, capture_output=True, text=True,
                                timeout=60)
        if result.returncode != 0:
            fail(f"{' '.join(command[:3])} failed: {result.stderr.strip()[-300:]}")
    files = {}
    for name in ("tls.crt", "tls.key", "ca.crt"):
        with open(os.path.join(directory, name)) as f:
            files[name] = f.read()
    return {"apiVersion": "v1", "kind": "Secret", "type": "kubernetes.io/tls",
            "metadata": {"name": spec["secretName"]}, "stringData": files}


def run_tls_overlay(vantage, kubectl, scratch, pods, token):
    """The TLS overlay's pods: the learner serves mutual TLS, its probe's
    command answers SERVING (a plaintext health check does not), and the
    actors train with it (one update)."""
    objects = k8s_render.render(kubectl, k8s_render.OVERLAYS["tls"])
    shorten_run(objects)
    set_token(objects, token)
    objects.append(make_certificate(os.path.join(scratch, "ca"),
                                    k8s_render.only(objects, "Certificate")))
    learner_set = k8s_render.find(objects, *LEARNER)
    claims = {t["metadata"]["name"]: os.path.join(scratch, "claim")
              for t in learner_set["spec"].get("volumeClaimTemplates", [])}
    for directory in set(claims.values()):
        os.makedirs(directory)
    learner = Pod(objects, learner_set, "tls-vantage-learner-0",
                  os.path.join(scratch, "learner"), claims, vantage, {})
    pods.append(learner)
    actors = [Pod(objects, k8s_render.find(objects, *ACTOR), f"tls-vantage-actor-{i}",
                  os.path.join(scratch, f"actor{i}"), {}, vantage,
                  service_ports(objects, learner))
              for i in range(k8s_render.find(objects, *ACTOR)["spec"].get("replicas", 1))]
    pods.extend(actors)
    learner.start(os.path.join(scratch, "learner.log"))
    wait_until(lambda: port_open(learner.ports[50051]), SERVE_TIMEOUT_S,
               "the TLS learner to serve", [learner])
    probe = k8s_render.container(learner_set)["readinessProbe"]["exec"]["command"]
    if probe[0] != "vantage":
        fail(f"the TLS overlay's probe runs {probe[0]}, expected vantage")
    argv = [vantage] + [learner.rewrite(a, {}) for a in probe[1:]]
    result = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    if result.returncode != 0 or "SERVING" not in result.stdout:
        fail(f"the TLS overlay's readiness probe command {' '.join(argv)}: exit "
             f"{result.returncode}, stdout {result.stdout.strip()!r}, stderr "
             f"{result.stderr.strip()[-300:]!r}")
    plaintext = health(vantage, learner.ports[50051], 3)
    if plaintext.returncode == 0:
        fail("a plaintext `vantage health` passed against the TLS learner")
    for pod in actors:
        pod.start(os.path.join(scratch, pod.name + ".log"))
    run_dir = k8s_render.flag_values(learner.args)["--run_dir"]
    wait_until(lambda: len(read_progress(run_dir)[1]) >= 1, RUN_TIMEOUT_S,
               "an update of the TLS run", [learner] + actors)
    for pod in [learner] + actors:
        pod.process.send_signal(signal.SIGTERM)
    for pod in [learner] + actors:
        try:
            code = pod.process.wait(timeout=pod.grace_s)
        except subprocess.TimeoutExpired:
            fail(f"{pod.name} did not end within {pod.grace_s} s of SIGTERM")
        if code != 0:
            fail(f"{pod.name} exited {code} at SIGTERM: {tail(pod.log)}")


# --- driver --------------------------------------------------------------------

def run_test(args, scratch, pods):
    vantage = os.path.abspath(args.vantage)
    if not os.access(vantage, os.X_OK):
        fail(f"{vantage} is not an executable vantage binary")
    check_binary_has_new_commands(vantage)
    kubectl = k8s_render.kubectl_path(args.kubectl)
    objects = k8s_render.render(kubectl, k8s_render.BASE)
    steps, batch, every = shorten_run(objects)
    rollout = batch // int(k8s_render.run_config(objects)["distributed"]["actors"])
    print(f"run: {steps} steps, {batch} per update, a checkpoint every {every} updates",
          flush=True)

    check_placeholder_refused(objects, vantage, os.path.join(scratch, "placeholder"), pods)
    print("ok: the pods refuse the empty placeholder token", flush=True)
    token = secrets.token_hex(32)
    set_token(objects, token)

    logs = os.path.join(scratch, "logs")
    os.makedirs(logs)
    learner_set = k8s_render.find(objects, *LEARNER)
    claims = {}
    for template in learner_set["spec"].get("volumeClaimTemplates", []):
        claim = f"{template['metadata']['name']}-{learner_set['metadata']['name']}-0"
        claims[template["metadata"]["name"]] = os.path.join(scratch, "claims", claim)
        os.makedirs(claims[template["metadata"]["name"]])
    learner = Pod(objects, learner_set, "vantage-learner-0",
                  os.path.join(scratch, "pods", "vantage-learner-0"), claims, vantage, {})
    pods.append(learner)
    ports = service_ports(objects, learner)
    actor_set = k8s_render.find(objects, *ACTOR)
    actors = []
    for i in range(actor_set["spec"].get("replicas", 1)):
        # A Deployment's pods are named DEPLOYMENT-HASH-SUFFIX.
        name = f"vantage-actor-5c7d9f8b6-local{i}"
        actors.append(Pod(objects, actor_set, name, os.path.join(scratch, "pods", name),
                          {}, vantage, ports))
    pods.extend(actors)
    run_dir = k8s_render.flag_values(learner.args)["--run_dir"]
    print("learner: " + " ".join(learner.argv), flush=True)
    print("actor 0: " + " ".join(actors[0].argv), flush=True)

    started = time.monotonic()
    started_wall = time.time()
    learner.start(os.path.join(logs, "learner-0.log"))
    wait_until(lambda: port_open(learner.ports[50051]), SERVE_TIMEOUT_S,
               "the learner to serve", [learner])
    check_health(vantage, learner)
    print("ok: vantage health answers SERVING (and fails on a closed port)", flush=True)
    for pod in actors:
        pod.start(os.path.join(logs, pod.name + ".log"))
    actor_pids = [pod.process.pid for pod in actors]

    def past_checkpoint():
        _, rows = read_progress(run_dir)
        version = newest_checkpoint(run_dir)
        return version >= 1 and len(rows) > version
    wait_until(past_checkpoint, RUN_TIMEOUT_S,
               "a checkpoint and a progress row past it", [learner] + actors)
    check_metrics(learner, "vantage_learner_", objects)
    check_metrics(actors[0], "vantage_actor_", objects)
    print("ok: the metrics endpoints answer only with the Secret's basic auth", flush=True)

    print(f"peak RSS: learner {peak_rss_mb(learner.process):.0f} MiB, actor "
          f"{peak_rss_mb(actors[0].process):.0f} MiB", flush=True)
    learner.process.send_signal(signal.SIGKILL)
    learner.process.wait(timeout=30)
    header, kept = read_progress(run_dir)
    checkpoint = newest_checkpoint(run_dir)
    if kept and int(kept[-1].split(",")[0]) >= steps:
        fail("the learner finished before it was killed; the test needs a longer run")
    actor_log_sizes = [os.path.getsize(pod.log) for pod in actors]
    print(f"killed the learner (SIGKILL) after {len(kept)} updates, newest checkpoint "
          f"{checkpoint}, {time.monotonic() - started:.1f} s in", flush=True)
    time.sleep(2)  # the actors notice, as while a kubelet restarts the container

    restart_log = os.path.join(logs, "learner-0.restart.log")
    learner.start(restart_log)
    deadline = time.monotonic() + RUN_TIMEOUT_S
    while learner.alive():
        for pod in actors:
            # Exit 0 once told the run is over, which the learner says as it
            # finishes; any other exit is a failure.
            if not pod.alive() and not (pod.process.returncode == 0 and
                                        RUN_OVER in open(pod.log).read()):
                fail(f"{pod.name} exited ({pod.process.returncode}) while the learner "
                     f"resumed: {tail(pod.log)}")
        if time.monotonic() > deadline:
            fail(f"the restarted learner did not finish in {RUN_TIMEOUT_S} s: "
                 f"{tail(restart_log)}")
        time.sleep(0.2)
    if learner.process.returncode != 0:
        fail(f"the restarted learner exited {learner.process.returncode}: {tail(restart_log)}")
    log = open(restart_log).read()
    resumed = re.search(r"resum\w* .*?policy version (\d+)", log)
    if not re.search(r"\bresuming\b", log, re.I):
        fail(f"the restarted learner's log does not say it resumes: {tail(restart_log)}")
    if resumed and int(resumed.group(1)) != checkpoint:
        fail(f"the learner resumed from policy version {resumed.group(1)}, the newest "
             f"checkpoint was {checkpoint}")
    final_header, rows = read_progress(run_dir)
    if final_header != header:
        fail("progress.csv's header changed on resume")
    raised = any("now grants" in open(os.path.join(logs, name)).read()
                 for name in ("learner-0.log", "learner-0.restart.log"))
    check_progress(header, rows, kept, steps, batch, rollout, checkpoint, raised)
    print(f"ok: the learner resumed from update {checkpoint} and finished: {len(rows)} "
          f"rows, {steps} steps, {time.monotonic() - started:.1f} s in", flush=True)

    for pod, pid, size in zip(actors, actor_pids, actor_log_sizes):
        if pod.process.pid != pid:
            fail(f"{pod.name} is not the process started before the learner's restart")
        with open(pod.log, errors="replace") as f:
            f.seek(size)
            if "registered as actor" not in f.read():
                fail(f"{pod.name} did not register again with the restarted learner: "
                     f"{tail(pod.log)}")
    print("ok: the same actor processes reconnected by themselves", flush=True)

    # The pods run the same args: their environments' seeds must still
    # differ, or every actor would replay the same resets.
    seeds = {}
    for pod in actors:
        with open(pod.log, errors="replace") as f:
            found = re.search(r"registered as actor \d+, .*env seed (\d+)", f.read())
        if not found:
            fail(f"{pod.name} did not log its env seed: {tail(pod.log)}")
        seeds[pod.name] = found.group(1)
    if len(actors) > 1 and len(set(seeds.values())) != len(actors):
        fail(f"actor pods share env seeds: {seeds}")
    print(f"ok: the actor pods' env seeds differ: {seeds}", flush=True)

    # The finished learner told the actors the run is over: they end by
    # themselves, exit 0, rather than reconnecting to it forever.
    for pod in actors:
        try:
            code = pod.process.wait(timeout=pod.grace_s)
        except subprocess.TimeoutExpired:
            fail(f"{pod.name} still runs {pod.grace_s} s after the run ended: "
                 f"{tail(pod.log)}")
        if code != 0 or RUN_OVER not in open(pod.log).read():
            fail(f"{pod.name} exited {code} after the run: {tail(pod.log)}")
    print("ok: told the run is over, the actors ended by themselves with exit 0",
          flush=True)

    # The root filesystem is read-only in the pods (and HOME is on it):
    # nothing may have been written outside the writable volumes. The
    # ConfigMap and Secret files were written before the processes started.
    for pod in [learner] + actors:
        for directory, _, files in os.walk(pod.root):
            for name in files:
                path = os.path.join(directory, name)
                if os.path.getmtime(path) >= started_wall and \
                        not any(path.startswith(d + "/") for d in pod.writable):
                    fail(f"{pod.name} wrote {path}, which the read-only root "
                         "filesystem would refuse")

    run_tls_overlay(vantage, kubectl, os.path.join(scratch, "tls"), pods, token)
    print("ok: TLS overlay: its probe command answers SERVING over mutual TLS (a "
          "plaintext check fails) and the actors train", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vantage", required=True, help="the vantage binary")
    parser.add_argument("--kubectl", default="kubectl", help="kubectl (on PATH)")
    parser.add_argument("--keep", action="store_true",
                        help="keep the scratch directory (logs, run directory)")
    args = parser.parse_args()
    k8s_render.stop_on_sigterm()
    scratch = tempfile.mkdtemp(prefix="vantage-k8s-pods-")
    pods = []
    failure = None
    try:
        run_test(args, scratch, pods)
    except (TestFailure, subprocess.TimeoutExpired, OSError, KeyError) as error:
        failure = str(error) if isinstance(error, TestFailure) \
            else f"{type(error).__name__}: {error}"
    finally:
        for pod in pods:
            if pod.alive():
                pod.process.kill()
            if pod.process is not None:
                pod.process.wait()
        left = [p.name for p in pods if p.process is not None and p.process.poll() is None]
        if left and failure is None:
            failure = f"processes left behind: {left}"
    if failure is not None:
        print(f"FAIL: {failure}")
        print(f"logs and run directory kept in {scratch}")
        print("0 passed, 1 failed")
        return 1
    if args.keep:
        print(f"kept {scratch}")
    else:
        shutil.rmtree(scratch, ignore_errors=True)
    print("1 passed, 0 failed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
