"""Shared by the deploy/k8s tests: rendering the kustomizations and reading
the rendered objects. Needs Debian's python3-yaml and a kubectl on PATH."""

import base64
import ctypes
import json
import os
import shutil
import signal
import subprocess

import yaml

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
K8S = os.path.join(REPO, "deploy", "k8s")
BASE = os.path.join(K8S, "base")
OVERLAYS = {
    "tls": os.path.join(K8S, "overlays", "tls"),
    "prometheus-operator": os.path.join(K8S, "overlays", "prometheus-operator"),
}


class TestFailure(Exception):
    """A check failed; the message says which and why, on one line."""


def die_with_parent():
    """For Popen's preexec_fn: the child gets SIGKILL when the test process
    ends, however it ends (a ctest timeout's SIGKILL included), so no
    vantage process outlives a test."""
    PR_SET_PDEATHSIG = 1
    ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


class Stopped(BaseException):
    """SIGTERM reached the test: not a check's failure, the end of the test."""


def stop_on_sigterm():
    """SIGTERM to the test ends it through its cleanup (finally blocks)."""
    def handler(signum, _):
        raise Stopped(f"stopped by signal {signum}")
    signal.signal(signal.SIGTERM, handler)


def kubectl_path(kubectl):
    path = shutil.which(kubectl)
    if path is None:
        raise TestFailure(
            f"{kubectl} is not on PATH (Debian's package kubernetes-client "
            "provides kubectl)")
    return path


def render(kubectl, directory):
    """The objects `kubectl kustomize DIRECTORY` renders, in its order."""
    result = subprocess.run([kubectl, "kustomize", directory],
                            capture_output=True, text=True, timeout=120)
    if result.returncode != 0:
        lines = [line for line in result.stderr.splitlines()
                 if line.strip() and "is deprecated" not in line]
        raise TestFailure(
            f"`kubectl kustomize {os.path.relpath(directory, REPO)}` failed "
            f"(exit {result.returncode}): {' | '.join(lines)[-600:]}")
    try:
        objects = [o for o in yaml.safe_load_all(result.stdout) if o is not None]
    except yaml.YAMLError as error:
        raise TestFailure(f"the rendering of {directory} is not YAML: {error}")
    if not objects:
        raise TestFailure(f"`kubectl kustomize {directory}` rendered nothing")
    return objects


def find(objects, kind, name):
    matches = [o for o in objects
               if o.get("kind") == kind and o.get("metadata", {}).get("name") == name]
    if len(matches) != 1:
        raise TestFailure(
            f"expected one {kind}/{name} in the rendering, found {len(matches)}")
    return matches[0]


def only(objects, kind):
    matches = [o for o in objects if o.get("kind") == kind]
    if len(matches) != 1:
        raise TestFailure(f"expected one {kind} in the rendering, found {len(matches)}")
    return matches[0]


def container(workload):
    containers = workload["spec"]["template"]["spec"].get("containers", [])
    if len(containers) != 1:
        raise TestFailure(
            f"{workload['kind']}/{workload['metadata']['name']} has "
            f"{len(containers)} containers; these tests expect one")
    return containers[0]


def config_map_data(config_map, key):
    data = config_map.get("data", {})
    if key not in data:
        raise TestFailure(f"ConfigMap/{config_map['metadata']['name']} has no key {key}")
    return data[key]


def run_config(objects):
    """The run config JSON of the ConfigMap vantage-run (key run.json)."""
    text = config_map_data(find(objects, "ConfigMap", "vantage-run"), "run.json")
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise TestFailure(f"ConfigMap/vantage-run run.json is not JSON: {error}")


def env_value(objects, entry, pod_name):
    """The value of one container env entry (value, ConfigMap or Secret key,
    or a downward-API field), as the kubelet would set it."""
    if "value" in entry:
        return entry["value"]
    source = entry.get("valueFrom", {})
    if "configMapKeyRef" in source:
        ref = source["configMapKeyRef"]
        return config_map_data(find(objects, "ConfigMap", ref["name"]), ref["key"])
    if "secretKeyRef" in source:
        ref = source["secretKeyRef"]
        return secret_data(find(objects, "Secret", ref["name"]))[ref["key"]]
    if "fieldRef" in source:
        field = source["fieldRef"]["fieldPath"]
        if field == "metadata.name":
            return pod_name
        if field == "metadata.namespace":
            return "default"
        raise TestFailure(f"env {entry['name']}: fieldRef {field} is not modelled here")
    raise TestFailure(f"env {entry['name']}: no value and no source this test knows")


def secret_data(secret):
    """A Secret's keys and values (stringData over base64 data, as the API
    server merges them)."""
    values = {k: base64.b64decode(v).decode() for k, v in secret.get("data", {}).items()}
    values.update(secret.get("stringData", {}))
    return values


def expand(text, env):
    """Kubernetes' $(VAR) expansion of command, args and env values: $(NAME)
    of a defined NAME becomes its value, $$ becomes $, anything else stays."""
    out = []
    i = 0
    while i < len(text):
        if text.startswith("$$", i):
            out.append("$")
            i += 2
            continue
        if text.startswith("$(", i):
            end = text.find(")", i + 2)
            if end != -1 and text[i + 2:end] in env:
                out.append(env[text[i + 2:end]])
                i = end + 1
                continue
        out.append(text[i])
        i += 1
    return "".join(out)


def container_env(objects, workload, pod_name):
    env = {}
    for entry in container(workload).get("env", []):
        value = env_value(objects, entry, pod_name)
        env[entry["name"]] = expand(value, env) if "value" in entry else value
    return env


def flag_values(args):
    """{--flag: value} of args of the form --flag=value (or --flag: "")."""
    values = {}
    for arg in args:
        if arg.startswith("--"):
            name, _, value = arg.partition("=")
            values[name] = value
    return values
