#!/usr/bin/python3
"""Checks the Kubernetes manifests under deploy/k8s without a cluster.

usage: k8s_manifests_test.py --vantage=PATH_TO_BINARY [--kubectl=kubectl]
                             [--npm_dir=DIR]

- `kubectl kustomize` renders the base and each overlay;
- every rendered object is valid against the Kubernetes API schemas of the
  npm packages kubernetes-models, @kubernetes-models/prometheus-operator and
  @kubernetes-models/cert-manager (validate_objects.js, run with Node.js;
  `npm ci` installs the pinned package-lock.json into --npm_dir, by default
  beside the binary, once per lock file), and the validator is shown to
  refuse broken objects;
- the objects agree with each other (selectors, ports, ConfigMap and Secret
  keys, every file a flag names is on a volume of its pod, the monitors'
  targets and credentials, the TLS overlay's certificate names);
- the binary accepts them: every flag in the containers' args and probes is
  one of its command's flags, and the learner, started on the ConfigMap's
  run.json, resolves exactly that config (its run directory's config.json);
- the actor Deployment's --env and --envs equal the run config's
  training.env and distributed.envs_per_actor (its replicas are free: the
  learner's pool is elastic, docs/deploy.md "Scaling the actors").

Prints `ok NAME` or `FAIL NAME: WHY` per check, then `N passed, N failed`;
exits 1 if any check failed.
"""

import argparse
import copy
import fcntl
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
import k8s_render  # noqa: E402
from k8s_render import TestFailure  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
LEARNER = ("StatefulSet", "vantage-learner")
ACTOR = ("Deployment", "vantage-actor")
# What cert-manager writes into a Certificate's Secret.
CERT_MANAGER_SECRET_KEYS = {"tls.crt", "tls.key", "ca.crt"}


def fail(message):
    raise TestFailure(message)


# --- Node.js schema validation ----------------------------------------------

def install_validator(npm_dir):
    """`npm ci` of package-lock.json into npm_dir, unless the same lock file
    is installed there already. Returns the node_modules directory."""
    for tool in ("node", "npm"):
        if shutil.which(tool) is None:
            fail(f"{tool} is not on PATH (Debian's packages nodejs and npm)")
    os.makedirs(npm_dir, exist_ok=True)
    with open(os.path.join(HERE, "package-lock.json"), "rb") as f:
        lock_hash = hashlib.sha256(f.read()).hexdigest()
    stamp = os.path.join(npm_dir, "installed-lock.sha256")
    with open(os.path.join(npm_dir, ".install-lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if os.path.exists(stamp) and open(stamp).read().strip() == lock_hash \
                and os.path.isdir(os.path.join(npm_dir, "node_modules")):
            return os.path.join(npm_dir, "node_modules")
        for name in ("package.json", "package-lock.json"):
            shutil.copyfile(os.path.join(HERE, name), os.path.join(npm_dir, name))
        result = subprocess.run(
            ["npm", "ci", "--ignore-scripts", "--no-audit", "--no-fund",
             "--loglevel=error"],
            cwd=npm_dir, capture_output=True, text=True, timeout=600)
        if result.returncode != 0:
            fail(f"npm ci in {npm_dir} failed (exit {result.returncode}): "
                 f"{' '.join(result.stderr.split())[-500:]}")
        with open(stamp, "w") as f:
            f.write(lock_hash + "\n")
    return os.path.join(npm_dir, "node_modules")


def validate(node_modules, objects):
    """validate_objects.js's verdicts: (exit code, {"KIND/NAME": line})."""
    env = dict(os.environ, NODE_PATH=node_modules)
    result = subprocess.run(
        ["node", os.path.join(HERE, "validate_objects.js")],
        input=json.dumps(objects), capture_output=True, text=True, env=env,
        timeout=120)
    if result.returncode not in (0, 1) or result.stderr.strip():
        fail(f"validate_objects.js broke (exit {result.returncode}): "
             f"{' '.join(result.stderr.split())[-500:]}")
    verdicts = {}
    for line in result.stdout.splitlines():
        match = re.match(r"(ok|FAIL) (\S+?)(: .*)?$", line)
        if match is None:
            fail(f"validate_objects.js printed an unexpected line: {line}")
        verdicts[match.group(2)] = line
    if len(verdicts) != len(objects):
        fail(f"validate_objects.js judged {len(verdicts)} of {len(objects)} objects")
    return result.returncode, verdicts


def check_schemas(node_modules, objects):
    code, verdicts = validate(node_modules, objects)
    failed = [line for line in verdicts.values() if not line.startswith("ok ")]
    if failed or code != 0:
        fail("; ".join(failed) or f"validate_objects.js exited {code}")


def check_validator_refuses(node_modules, base):
    """The schema check can fail: each deliberately broken copy of a base
    object must be refused, for the reason planted."""
    learner = k8s_render.find(base, *LEARNER)
    broken = []

    def planted(name, why, change):
        obj = copy.deepcopy(learner)
        obj["metadata"]["name"] = name
        change(obj)
        broken.append((obj, why))

    spec = lambda o: o["spec"]
    first = lambda o: o["spec"]["template"]["spec"]["containers"][0]
    planted("replicas-as-string", "must be integer",
            lambda o: spec(o).__setitem__("replicas", "1"))
    planted("misspelt-probe", "unknown field",
            lambda o: first(o).__setitem__("readinesProbe", first(o).pop("readinessProbe")))
    planted("grpc-probe-without-port", "must have required property 'port'",
            lambda o: first(o)["livenessProbe"]["grpc"].pop("port"))
    planted("no-template", "must have required property 'template'",
            lambda o: spec(o).pop("template"))
    planted("bad-quantity", "resources/limits/memory",
            lambda o: first(o)["resources"]["limits"].__setitem__("memory", "4 gigs"))
    unknown_kind = {"apiVersion": "apps/v1", "kind": "StatefulSett",
                    "metadata": {"name": "unknown-kind"}}
    broken.append((unknown_kind, "no schema"))
    monitor = {"apiVersion": "monitoring.coreos.com/v1", "kind": "ServiceMonitor",
               "metadata": {"name": "monitor-interval"},
               "spec": {"selector": {}, "endpoints": [{"port": "metrics",
                                                       "interval": "often"}]}}
    broken.append((monitor, "interval must match pattern"))
    certificate = {"apiVersion": "cert-manager.io/v1", "kind": "Certificate",
                   "metadata": {"name": "certificate-usage"},
                   "spec": {"secretName": "s", "issuerRef": {"name": "i"},
                            "dnsNames": ["a"], "usages": ["serverauth"]}}
    broken.append((certificate, "usages/0 must be equal to one of the allowed values"))
    good = copy.deepcopy(learner)
    good["metadata"]["name"] = "unchanged"
    code, verdicts = validate(node_modules, [o for o, _ in broken] + [good])
    if code != 1:
        fail(f"validate_objects.js exited {code} on broken objects, expected 1")
    for obj, why in broken:
        line = verdicts[f"{obj['kind']}/{obj['metadata']['name']}"]
        if not line.startswith("FAIL ") or why.replace("'", "") not in line.replace("'", ""):
            fail(f"broken {obj['kind']}/{obj['metadata']['name']} not refused for "
                 f"'{why}': {line}")
    if not verdicts["StatefulSet/unchanged"].startswith("ok "):
        fail(f"the unchanged learner was refused: {verdicts['StatefulSet/unchanged']}")


# --- consistency within a rendering -----------------------------------------

def labels_match(selector, labels):
    return all(labels.get(k) == v for k, v in selector.items())


def secrets_with_keys(objects):
    """Secret name -> keys: the rendered Secrets and those cert-manager
    makes from a rendered Certificate."""
    secrets = {o["metadata"]["name"]: set(k8s_render.secret_data(o))
               for o in objects if o["kind"] == "Secret"}
    for cert in (o for o in objects if o["kind"] == "Certificate"):
        secrets.setdefault(cert["spec"]["secretName"], set()).update(CERT_MANAGER_SECRET_KEYS)
    return secrets


def volume_files(objects, volume, where):
    """The files a ConfigMap or Secret volume holds (relative paths), or
    None for a writable volume (emptyDir, claim)."""
    if "configMap" in volume:
        cm = k8s_render.find(objects, "ConfigMap", volume["configMap"]["name"])
        keys = set(cm.get("data", {}))
        items = volume["configMap"].get("items")
    elif "secret" in volume:
        name = volume["secret"]["secretName"]
        keys = secrets_with_keys(objects).get(name)
        if keys is None:
            fail(f"{where}: volume {volume['name']} names Secret {name}, which is "
                 "neither rendered nor made by a rendered Certificate")
        items = volume["secret"].get("items")
    elif "emptyDir" in volume or "persistentVolumeClaim" in volume:
        return None
    else:
        fail(f"{where}: volume {volume['name']} is of a kind this test does not know")
    if items is None:
        return keys
    for item in items:
        if item["key"] not in keys:
            fail(f"{where}: volume {volume['name']} wants key {item['key']}, "
                 f"which its source lacks (has {sorted(keys)})")
    return {item["path"] for item in items}


def mounts(objects, workload):
    """[(mountPath, files or None)] of the workload's container."""
    where = f"{workload['kind']}/{workload['metadata']['name']}"
    spec = workload["spec"]["template"]["spec"]
    volumes = {v["name"]: v for v in spec.get("volumes", [])}
    claims = {c["metadata"]["name"] for c in workload["spec"].get("volumeClaimTemplates", [])}
    result = []
    for mount in k8s_render.container(workload).get("volumeMounts", []):
        if mount["name"] in volumes:
            result.append((mount["mountPath"],
                           volume_files(objects, volumes[mount["name"]], where)))
        elif mount["name"] in claims:
            result.append((mount["mountPath"], None))
        else:
            fail(f"{where}: volumeMount {mount['name']} names no volume or claim template")
    return result


def check_path_on_volume(objects, workload, flag, path):
    where = f"{workload['kind']}/{workload['metadata']['name']}"
    best = None
    for mount_path, files in mounts(objects, workload):
        prefix = mount_path.rstrip("/") + "/"
        if (path == mount_path or path.startswith(prefix)) and \
                (best is None or len(mount_path) > len(best[0])):
            best = (mount_path, files)
    if best is None:
        fail(f"{where}: {flag}={path} is on no volume of the pod (the root "
             "filesystem is read-only and the image's)")
    mount_path, files = best
    relative = os.path.relpath(path, mount_path)
    if files is not None and relative not in files:
        fail(f"{where}: {flag}={path}: the volume at {mount_path} holds "
             f"{sorted(files)}, not {relative}")


def container_port(workload, name):
    for port in k8s_render.container(workload).get("ports", []):
        if port.get("name") == name:
            return port["containerPort"]
    fail(f"{workload['kind']}/{workload['metadata']['name']} has no container port {name}")


def port_of(address):
    host, _, port = address.rpartition(":")
    if not host or not port.isdigit():
        fail(f"{address} is not HOST:PORT")
    return host, int(port)


def check_references(objects):
    learner = k8s_render.find(objects, *LEARNER)
    actor = k8s_render.find(objects, *ACTOR)
    service = k8s_render.find(objects, "Service", "vantage-learner")
    for workload in (learner, actor):
        where = f"{workload['kind']}/{workload['metadata']['name']}"
        template_labels = workload["spec"]["template"]["metadata"].get("labels", {})
        if not labels_match(workload["spec"]["selector"]["matchLabels"], template_labels):
            fail(f"{where}: the selector does not match the pod template's labels")
        annotations = workload["spec"]["template"]["metadata"].get("annotations", {})
        if annotations.get("prometheus.io/port") != str(container_port(workload, "metrics")) \
                or annotations.get("prometheus.io/path") != "/metrics" \
                or "prometheus.io/scrape" not in annotations:
            fail(f"{where}: the prometheus.io annotations do not name the metrics "
                 f"port and /metrics: {annotations}")
        c = k8s_render.container(workload)
        if c.get("command"):
            fail(f"{where}: sets command; the image's ENTRYPOINT (vantage) must run")
        secrets = secrets_with_keys(objects)
        for entry in c.get("env", []):
            ref = entry.get("valueFrom", {})
            if "configMapKeyRef" in ref:
                k8s_render.config_map_data(
                    k8s_render.find(objects, "ConfigMap", ref["configMapKeyRef"]["name"]),
                    ref["configMapKeyRef"]["key"])
            if "secretKeyRef" in ref and ref["secretKeyRef"]["key"] not in \
                    secrets.get(ref["secretKeyRef"]["name"], set()):
                fail(f"{where}: env {entry['name']} names a missing Secret key")
        paths = [(f, v) for f, v in k8s_render.flag_values(c.get("args", [])).items()
                 if v.startswith("/")]
        for probe in ("startupProbe", "readinessProbe", "livenessProbe"):
            command = c.get(probe, {}).get("exec", {}).get("command", [])
            paths += [(f"{probe} {f}", v)
                      for f, v in k8s_render.flag_values(command).items()
                      if v.startswith("/")]
        for flag, path in paths:
            check_path_on_volume(objects, workload, flag, path)
        host, port = port_of(k8s_render.flag_values(c["args"])["--metrics"])
        if port != container_port(workload, "metrics") or host != "0.0.0.0":
            fail(f"{where}: --metrics does not serve the metrics container port on 0.0.0.0")
    if learner["spec"].get("serviceName") != service["metadata"]["name"]:
        fail("StatefulSet/vantage-learner: serviceName is not the Service vantage-learner")
    pod_labels = lambda w: w["spec"]["template"]["metadata"].get("labels", {})
    if not labels_match(service["spec"]["selector"], pod_labels(learner)) or \
            labels_match(service["spec"]["selector"], pod_labels(actor)):
        fail("Service/vantage-learner must select the learner's pods and not the actors'")
    service_ports = {}
    for port in service["spec"]["ports"]:
        target = port.get("targetPort", port["port"])
        service_ports[port["name"]] = (port["port"], target if isinstance(target, int)
                                       else container_port(learner, target))
    if service_ports.get("grpc") != (50051, container_port(learner, "grpc")) or \
            service_ports.get("metrics") != (9100, container_port(learner, "metrics")):
        fail(f"Service/vantage-learner ports: expected grpc 50051 and metrics 9100 to "
             f"the learner's, got {service_ports}")
    learner_flags = k8s_render.flag_values(k8s_render.container(learner)["args"])
    if port_of(learner_flags["--listen"])[1] != container_port(learner, "grpc"):
        fail("StatefulSet/vantage-learner: --listen is not on the grpc container port")
    actor_flags = k8s_render.flag_values(k8s_render.container(actor)["args"])
    host, port = port_of(actor_flags["--learner"])
    if host != service["metadata"]["name"] or port != service_ports["grpc"][0]:
        fail(f"Deployment/vantage-actor: --learner={actor_flags['--learner']} is not "
             "the Service's grpc port")
    for monitor in (o for o in objects if o["kind"] in ("ServiceMonitor", "PodMonitor")):
        check_monitor(objects, monitor, learner, actor, service)


def check_monitor(objects, monitor, learner, actor, service):
    where = f"{monitor['kind']}/{monitor['metadata']['name']}"
    selector = monitor["spec"]["selector"].get("matchLabels", {})
    if monitor["kind"] == "ServiceMonitor":
        if not labels_match(selector, service["metadata"].get("labels", {})):
            fail(f"{where}: selects not the Service vantage-learner (its labels)")
        endpoints = monitor["spec"]["endpoints"]
        names = {p["name"] for p in service["spec"]["ports"]}
    else:
        labels = actor["spec"]["template"]["metadata"].get("labels", {})
        if not labels_match(selector, labels) or labels_match(
                selector, learner["spec"]["template"]["metadata"].get("labels", {})):
            fail(f"{where}: selects not the actor pods (only)")
        endpoints = monitor["spec"]["podMetricsEndpoints"]
        names = {p["name"] for p in k8s_render.container(actor).get("ports", [])}
    secrets = {o["metadata"]["name"]: k8s_render.secret_data(o)
               for o in objects if o["kind"] == "Secret"}
    for endpoint in endpoints:
        if endpoint.get("port") != "metrics" or "metrics" not in names:
            fail(f"{where}: scrapes port {endpoint.get('port')}, not the metrics port")
        auth = endpoint.get("basicAuth")
        if auth is None:
            fail(f"{where}: no basicAuth; the metrics endpoints require it")
        user = secrets.get(auth["username"]["name"], {}).get(auth["username"]["key"])
        token_key = auth["password"]["key"]
        if user != "vantage" or token_key not in secrets.get(auth["password"]["name"], {}):
            fail(f"{where}: basicAuth must be user vantage (a Secret key holding "
                 "'vantage') and the run's token")
    actor_token = k8s_render.flag_values(k8s_render.container(actor)["args"])["--auth_token_file"]
    if not actor_token.endswith("/" + token_key):
        fail(f"{where}: the basic auth password is key {token_key}, the pods' token file "
             f"is {actor_token}")


def check_tls(objects):
    learner = k8s_render.find(objects, *LEARNER)
    actor = k8s_render.find(objects, *ACTOR)
    cert = k8s_render.only(objects, "Certificate")
    files = {}
    for workload, role in ((learner, "learner"), (actor, "actor")):
        flags = k8s_render.flag_values(k8s_render.container(workload)["args"])
        for flag in ("--tls_cert", "--tls_key", "--tls_ca"):
            if not flags.get(flag):
                fail(f"{role}: no {flag} in the TLS overlay")
        files[role] = {f: flags[f] for f in ("--tls_cert", "--tls_key", "--tls_ca")}
        volumes = workload["spec"]["template"]["spec"]["volumes"]
        if not any(v.get("secret", {}).get("secretName") == cert["spec"]["secretName"]
                   for v in volumes):
            fail(f"{role}: the Certificate's Secret {cert['spec']['secretName']} is not a volume")
    grpc_port = container_port(learner, "grpc")
    c = k8s_render.container(learner)
    for probe in ("startupProbe", "readinessProbe", "livenessProbe"):
        if "grpc" in c.get(probe, {}):
            fail(f"learner {probe}: a gRPC probe cannot speak TLS")
        command = c.get(probe, {}).get("exec", {}).get("command", [])
        flags = k8s_render.flag_values(command)
        if command[:2] != ["vantage", "health"] or \
                flags.get("--learner") != f"127.0.0.1:{grpc_port}" or \
                any(flags.get(f) != files["learner"][f] for f in files["learner"]):
            fail(f"learner {probe}: expected `vantage health --learner=127.0.0.1:"
                 f"{grpc_port}` with the learner's TLS files, got {command}")
    spec = cert["spec"]
    service_host = port_of(k8s_render.flag_values(
        k8s_render.container(actor)["args"])["--learner"])[0]
    if service_host not in spec.get("dnsNames", []):
        fail(f"Certificate: dnsNames {spec.get('dnsNames')} lack {service_host}, "
             "the name the actors dial")
    if "127.0.0.1" not in spec.get("ipAddresses", []):
        fail("Certificate: ipAddresses lack 127.0.0.1, which the health probes dial")
    if not {"server auth", "client auth"} <= set(spec.get("usages", [])):
        fail("Certificate: usages need server auth (learner) and client auth (actors)")


# --- the binary --------------------------------------------------------------

def help_flags(vantage, command):
    result = subprocess.run([vantage, "help", command], capture_output=True,
                            text=True, timeout=60)
    if result.returncode != 0:
        fail(f"`vantage help {command}` failed (exit {result.returncode}): "
             f"{' '.join((result.stderr or result.stdout).split())[-300:]}")
    return set(re.findall(r"^\s+--([A-Za-z0-9_]+)=", result.stdout, re.M))


def check_flags_known(vantage, objects, tls):
    learner = k8s_render.container(k8s_render.find(objects, *LEARNER))
    actor = k8s_render.container(k8s_render.find(objects, *ACTOR))
    commands = [("learner", learner["args"]), ("actor", actor["args"])]
    if tls:
        commands.append(("health", learner["readinessProbe"]["exec"]["command"][1:]))
    for command, args in commands:
        if not args or args[0] != command:
            fail(f"the {command} container's args must start with the subcommand "
                 f"{command}, got {args[:1]}")
        known = help_flags(vantage, command)
        for flag in k8s_render.flag_values(args[1:]):
            if flag[2:] not in known:
                fail(f"`vantage {command}` has no flag {flag} (`vantage help {command}`)")
    learner_flags = k8s_render.flag_values(learner["args"])
    if "--resume_if_exists" not in learner_flags or "--run_dir" not in learner_flags:
        fail("the learner needs --run_dir and --resume_if_exists to resume after a restart")
    if k8s_render.flag_values(actor["args"]).get("--max_reconnects") != "-1":
        fail("the actors need --max_reconnects=-1 to outlive learner restarts")


def check_actors_match_run(objects):
    run = k8s_render.run_config(objects)
    actor = k8s_render.find(objects, *ACTOR)
    try:
        envs_per_actor = run["distributed"]["envs_per_actor"]
        env = run["training"]["env"]
    except KeyError as error:
        fail(f"run.json lacks {error} (a distributed run's config.json has it)")
    if run.get("mode") != "distributed":
        fail(f"run.json's mode is {run.get('mode')}, not distributed")
    env_vars = k8s_render.container_env(objects, actor, "vantage-actor-0")
    flags = k8s_render.flag_values(
        [k8s_render.expand(a, env_vars) for a in k8s_render.container(actor)["args"]])
    if flags.get("--env") != env:
        fail(f"the actors get --env={flags.get('--env')} but run.json's training.env "
             f"is {env}")
    if flags.get("--envs") != str(envs_per_actor):
        fail(f"the actors get --envs={flags.get('--envs')} but run.json's "
             f"distributed.envs_per_actor is {envs_per_actor}")


def check_learner_resolves_run_json(vantage, objects):
    """Starts the learner on run.json in a scratch run directory and compares
    the config it resolved (RUN_DIR/config.json) with run.json."""
    run = k8s_render.run_config(objects)
    scratch = tempfile.mkdtemp(prefix="vantage-k8s-config-")
    process = None
    try:
        path = os.path.join(scratch, "run.json")
        with open(path, "w") as f:
            f.write(k8s_render.config_map_data(
                k8s_render.find(objects, "ConfigMap", "vantage-run"), "run.json"))
        port_file = os.path.join(scratch, "port")
        log_path = os.path.join(scratch, "learner.log")
        with open(log_path, "w") as log:
            process = subprocess.Popen(
                [vantage, "learner", f"--config={path}",
                 f"--run_dir={os.path.join(scratch, 'run')}",
                 "--listen=127.0.0.1:0", f"--port_file={port_file}"],
                stdout=log, stderr=subprocess.STDOUT,
                preexec_fn=k8s_render.die_with_parent)
        deadline = time.monotonic() + 60
        while not os.path.exists(port_file) and process.poll() is None:
            if time.monotonic() > deadline:
                fail("the learner did not serve within 60 s on run.json")
            time.sleep(0.1)
        if process.poll() is not None:
            fail(f"the learner refused run.json (exit {process.returncode}): "
                 f"{' '.join(open(log_path).read().split())[-400:]}")
        with open(os.path.join(scratch, "run", "config.json")) as f:
            resolved = json.load(f)
        process.send_signal(signal.SIGTERM)
        code = process.wait(timeout=60)
        if code != 0:
            fail(f"the learner on run.json exited {code} at SIGTERM")
        differences = [key for key in sorted(set(run) | set(resolved))
                       if run.get(key) != resolved.get(key)]
        if differences:
            key = differences[0]
            fail(f"the learner resolved run.json's '{key}' to {resolved.get(key)}, "
                 f"run.json has {run.get(key)}: run.json should be a run's whole "
                 "config.json")
    finally:
        if process is not None and process.poll() is None:
            process.kill()
            process.wait()
        shutil.rmtree(scratch, ignore_errors=True)


# --- driver -------------------------------------------------------------------

def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vantage", required=True, help="the vantage binary")
    parser.add_argument("--kubectl", default="kubectl", help="kubectl (on PATH)")
    parser.add_argument("--npm_dir", default=None,
                        help="where npm ci installs the schema packages "
                             "(default: k8s-schema-npm beside the binary)")
    args = parser.parse_args()
    k8s_render.stop_on_sigterm()
    vantage = os.path.abspath(args.vantage)
    if not os.access(vantage, os.X_OK):
        print(f"FAIL setup: {vantage} is not an executable vantage binary")
        return 1
    npm_dir = os.path.abspath(args.npm_dir or os.path.join(
        os.path.dirname(vantage), "k8s-schema-npm"))

    results = []
    state = {}

    def run(name, check, *needs):
        missing = [n for n in needs if n not in state]
        if missing:
            results.append((name, f"not run: {', '.join(missing)} failed"))
        else:
            try:
                value = check()
                if value is not None:
                    state[name] = value
                results.append((name, None))
            except (TestFailure, subprocess.TimeoutExpired, KeyError, OSError) as error:
                results.append((name, f"{type(error).__name__}: {error}"
                                if not isinstance(error, TestFailure) else str(error)))
        why = results[-1][1]
        print(f"ok {name}" if why is None else f"FAIL {name}: {why}", flush=True)

    run("kubectl", lambda: k8s_render.kubectl_path(args.kubectl))
    kubectl = state.get("kubectl", args.kubectl)
    directories = {"base": k8s_render.BASE, **k8s_render.OVERLAYS}
    for name, directory in directories.items():
        run(f"render {name}", lambda d=directory: k8s_render.render(kubectl, d), "kubectl")
    run("npm ci", lambda: install_validator(npm_dir))
    run("validator refuses broken objects",
        lambda: check_validator_refuses(state["npm ci"], state["render base"]),
        "npm ci", "render base")
    for name in directories:
        rendered = f"render {name}"
        run(f"schema {name}",
            lambda r=rendered: check_schemas(state["npm ci"], state[r]), "npm ci", rendered)
        run(f"references {name}", lambda r=rendered: check_references(state[r]), rendered)
        run(f"flags known to the binary {name}",
            lambda r=rendered, n=name: check_flags_known(vantage, state[r], n == "tls"),
            rendered)
    run("tls overlay: certificate and probes", lambda: check_tls(state["render tls"]),
        "render tls")
    run("actors match run.json", lambda: check_actors_match_run(state["render base"]),
        "render base")
    run("learner resolves run.json to itself",
        lambda: check_learner_resolves_run_json(vantage, state["render base"]),
        "render base")

    failed = sum(1 for _, why in results if why is not None)
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
