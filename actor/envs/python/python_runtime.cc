#include "actor/envs/python/python_runtime.h"

#include <pybind11/embed.h>

#include <cstdio>
#include <mutex>

#include "absl/strings/str_cat.h"

namespace py = pybind11;

namespace vantage {
namespace {

// What is simpler said in Python than through the C API: finding the
// factory, describing spaces, formatting tracebacks, timing a plain loop.
constexpr char kBridge[] = R"PY(
import importlib
import importlib.util
import json
import os
import sys
import time
import traceback

import numpy as np


def _load_module(name):
    if name.endswith(".py") or os.sep in name:
        path = os.path.abspath(name)
        if not os.path.isfile(path):
            raise ModuleNotFoundError(f"no Python file {path}")
        module_name = os.path.splitext(os.path.basename(path))[0]
        # Its siblings import as they would beside a script.
        if os.path.dirname(path) not in sys.path:
            sys.path.insert(1, os.path.dirname(path))
        spec = importlib.util.spec_from_file_location(module_name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module
        spec.loader.exec_module(module)
        return module
    return importlib.import_module(name)


def make(target, kwargs_json):
    kwargs = json.loads(kwargs_json) if kwargs_json else {}
    if not isinstance(kwargs, dict):
        raise TypeError("--env_kwargs must be a JSON object, got "
                        + type(kwargs).__name__)
    if target.startswith("gym:"):
        import gymnasium
        return gymnasium.make(target[len("gym:"):], **kwargs)
    module_name, _, attribute = target[len("python:"):].rpartition(":")
    factory = _load_module(module_name)
    for part in attribute.split("."):
        factory = getattr(factory, part)
    if not callable(factory):
        raise TypeError(f"{attribute} in {module_name} is not callable")
    return factory(**kwargs)


def observation_entries(space):
    # ("single", [("", box)], False), or a Dict's or Tuple's entries in order
    # as ("dict" | "tuple", [(key, box), ...], whether a Dict holds an
    # "action_mask" key, which is the action mask, not an entry).
    spaces = getattr(space, "spaces", None)
    if spaces is None:
        return ("single", [("", describe_space(space, "observation"))], False)
    kind = type(space).__name__
    if isinstance(spaces, dict):
        container, items = "dict", list(spaces.items())
    else:
        container, items = "tuple", [(str(i), s) for i, s in enumerate(spaces)]
    has_mask = container == "dict" and "action_mask" in spaces
    entries = []
    for key, sub in items:
        if has_mask and key == "action_mask":
            continue
        path = f"observation[{key!r}]"
        if hasattr(sub, "spaces"):
            raise TypeError(f"{path} is a {type(sub).__name__} space inside the "
                            f"{kind} space; vantage takes one level of Dict or "
                            "Tuple (flatten the inner one)")
        described = describe_space(sub, path)
        if described[0] != "box":
            raise TypeError(f"{path} is a {type(sub).__name__} space; vantage "
                            "takes box entries (one-hot encode it into a Box)")
        entries.append((str(key), described))
    if not entries:
        raise TypeError(f"the observation space is a {kind} space without "
                        "entries")
    return (container, entries, has_mask)


def first_info_has_action_mask(env):
    _, info = env.reset(seed=0)
    return isinstance(info, dict) and "action_mask" in info


def describe_space(space, what):
    kind = type(space).__name__
    if hasattr(space, "spaces"):
        raise TypeError(
            f"the {what} space is a {kind} space; vantage takes a box or a "
            "discrete space: flatten it (gymnasium.wrappers."
            "FlattenObservation, or one Box of the concatenated parts)")
    shape = getattr(space, "shape", None)
    if hasattr(space, "nvec") and what == "action":
        start = np.asarray(getattr(space, "start", 0))
        if np.any(start != 0):
            raise TypeError(f"the {what} space is MultiDiscrete with a start; "
                            "vantage's discrete actions start at 0")
        nvec = np.asarray(space.nvec, dtype=np.int64)
        return ("multidiscrete", int(nvec.size), tuple(nvec.shape),
                np.dtype(space.dtype).str, nvec.ravel().tolist(), [])
    if (hasattr(space, "n") and shape is not None and tuple(shape) != ()
            and not hasattr(space, "low") and what == "action"):
        # MultiBinary: n choices of 2 (n may be a shape).
        shape = tuple(int(d) for d in shape)
        size = int(np.prod(shape))
        return ("multidiscrete", size, shape,
                np.dtype(getattr(space, "dtype", np.int8)).str, [2] * size, [])
    if hasattr(space, "n") and (shape is None or tuple(shape) == ()):
        start = int(getattr(space, "start", 0))
        if start != 0:
            raise TypeError(f"the {what} space is Discrete(start={start}); "
                            "vantage's discrete actions start at 0")
        return ("discrete", int(space.n), (), "", [], [])
    if shape is not None and hasattr(space, "low") and hasattr(
            space, "high") and hasattr(space, "dtype") and not hasattr(
                space, "nvec") and not hasattr(space, "n"):
        shape = tuple(int(d) for d in shape)
        low = np.broadcast_to(np.asarray(space.low, dtype=np.float64), shape)
        high = np.broadcast_to(np.asarray(space.high, dtype=np.float64), shape)
        return ("box", 0, shape, np.dtype(space.dtype).str,
                low.ravel().tolist(), high.ravel().tolist())
    raise TypeError(f"the {what} space is a {kind} space; vantage takes a box "
                    "(shape, dtype, low, high) or a discrete space (n)")


def max_episode_steps(env):
    spec = getattr(env, "spec", None)
    steps = getattr(spec, "max_episode_steps", None)
    if steps is None:
        steps = getattr(env, "max_episode_steps", None)
    return int(steps) if steps else 0


def describe_error(error_type, value, trace):
    lines = traceback.format_exception(error_type, value, trace)
    # The deepest frame of a real file: the user's code, not importlib's
    # or this bridge's.
    frames = [frame for frame in traceback.extract_tb(trace)
              if not frame.filename.startswith("<")]
    where = ""
    if frames:
        last = frames[-1]
        where = f" ({os.path.basename(last.filename)}:{last.lineno} in {last.name})"
    summary = traceback.format_exception_only(error_type, value)[-1].strip()
    return summary + where, "".join(lines)


def plain_loop(env, action, steps):
    """Steps/s of env stepped by a plain Python loop with one action."""
    space = env.action_space
    if describe_space(space, "action")[0] == "discrete":
        action = int(action[0])
    else:
        action = np.asarray(action, dtype=space.dtype).reshape(space.shape)
    episode = 1 << 20
    env.reset(seed=episode)
    start = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            episode += 1
            env.reset(seed=episode)
    return steps / (time.perf_counter() - start)
)PY";

std::once_flag started;

}  // namespace

void EnsurePythonInterpreter() {
  std::call_once(started, [] {
    // The process keeps its own SIGINT/SIGTERM handling.
    py::initialize_interpreter(/*init_signal_handlers=*/false);
    {
      py::module_ sys = py::module_::import("sys");
      sys.attr("path").attr("insert")(0, "");
      PythonBridge();
    }
    // Released for good: every call into Python takes it back.
    PyEval_SaveThread();
  });
}

py::module_& PythonBridge() {
  static py::module_* bridge = [] {
    auto* module = new py::module_(py::reinterpret_borrow<py::module_>(
        py::module_::import("types").attr("ModuleType")("_vantage_bridge")));
    py::exec(kBridge, module->attr("__dict__"));
    return module;
  }();
  return *bridge;
}

absl::Status PythonError(py::error_already_set& error,
                         const std::string& what) {
  std::string summary = error.what();
  try {
    py::tuple described = PythonBridge().attr("describe_error")(
        error.type(), error.value(), error.trace());
    summary = described[0].cast<std::string>();
    std::fprintf(stderr, "%s: Python traceback:\n%s", what.c_str(),
                 described[1].cast<std::string>().c_str());
  } catch (const py::error_already_set&) {
    // The exception's own text (error.what()) has to do.
  }
  return absl::InvalidArgumentError(absl::StrCat(what, ": ", summary));
}

}  // namespace vantage
