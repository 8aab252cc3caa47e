#include "actor/envs/python/python_env.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"
#include "actor/envs/python/python_observations.h"
#include "actor/envs/python/python_runtime.h"
#include "common/util/call_watch.h"
#include "common/util/state_bytes.h"

namespace py = pybind11;

namespace vantage {
namespace {

constexpr char kStateKind[] = "python_env";
constexpr uint32_t kStateVersion = 1;

// Runs `body` (which uses Python) with the GIL held; a Python exception
// becomes the caller's error naming the env `name` and its `call`, any
// other C++ exception from pybind11 (a failed cast) too. The names are
// joined only for an error: stepping builds no strings.
template <typename Result, typename Body>
absl::StatusOr<Result> WithPython(const std::string& name, const char* call,
                                  Body&& body) {
  // Watched from before the GIL is taken: a call that hangs holding it
  // stops every other environment's call at that point.
  const WatchedCall watched(name, call);
  py::gil_scoped_acquire gil;
  try {
    return body();
  } catch (py::error_already_set& error) {
    return PythonError(error, absl::StrCat(name, ": ", call));
  } catch (const std::exception& error) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": ", call, ": ", error.what()));
  }
}

class PythonEnv final : public Environment {
 public:
  static absl::StatusOr<std::unique_ptr<Environment>> Create(
      const std::string& name, const std::string& kwargs_json) {
    EnsurePythonInterpreter();
    std::unique_ptr<PythonEnv> env;
    {
      py::gil_scoped_acquire gil;  // its members are Python objects
      env.reset(new PythonEnv());
    }
    env->spec_.name = name;
    absl::StatusOr<bool> made = WithPython<bool>(name, "the factory", [&] {
      env->env_ = PythonBridge().attr("make")(name, kwargs_json);
      env->reset_ = env->env_.attr("reset");
      env->step_ = env->env_.attr("step");
      return true;
    });
    if (!made.ok()) return made.status();
    absl::StatusOr<bool> described =
        WithPython<bool>(name, "its spaces", [&] { return env->Describe(); });
    if (!described.ok()) return described.status();
    if (absl::Status status = CheckObservationLayout(env->spec_);
        !status.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": ", status.message()));
    }
    return std::unique_ptr<Environment>(std::move(env));
  }

  ~PythonEnv() override {
    py::gil_scoped_acquire gil;
    try {
      if (env_ && py::hasattr(env_, "close")) env_.attr("close")();
    } catch (py::error_already_set& error) {
      (void)PythonError(error, absl::StrCat(spec_.name, ": close()"));
    }
    step_ = py::object();
    reset_ = py::object();
    env_ = py::object();
  }

  const EnvSpec& spec() const override { return spec_; }

  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override {
    if (absl::Status status = CheckObservationBuffer(spec_, observation);
        !status.ok()) {
      return status;
    }
    absl::StatusOr<bool> done =
        WithPython<bool>(spec_.name, "reset()", [&]() -> absl::StatusOr<bool> {
          py::object result = reset_(py::arg("seed") = seed);
          if (!py::isinstance<py::tuple>(result) || py::len(result) != 2) {
            return absl::InvalidArgumentError(absl::StrCat(
                spec_.name, ": reset() returned ",
                py::str(result.get_type().attr("__name__")).cast<std::string>(),
                ", not (observation, info)"));
          }
          py::tuple parts = result.cast<py::tuple>();
          absl::Status written = WriteObservationAndMask(
              parts[0], parts[1], "reset()", false, observation);
          if (!written.ok()) return written;
          return true;
        });
    if (!done.ok()) return done.status();
    needs_reset_ = false;
    return absl::OkStatus();
  }

  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override {
    if (absl::Status status =
            CheckStep(spec_, needs_reset_, action, observation);
        !status.ok()) {
      return status;
    }
    absl::StatusOr<StepResult> result = WithPython<StepResult>(
        spec_.name, "step()", [&]() -> absl::StatusOr<StepResult> {
          py::object out = step_(Action(action));
          if (!py::isinstance<py::tuple>(out) || py::len(out) != 5) {
            return absl::InvalidArgumentError(absl::StrCat(
                spec_.name,
                ": step() must return (observation, reward, terminated, "
                "truncated, info) as Gymnasium does; it returned ",
                py::isinstance<py::tuple>(out)
                    ? absl::StrCat("a tuple of ", py::len(out))
                    : py::str(out.get_type().attr("__name__"))
                          .cast<std::string>()));
          }
          py::tuple parts = out.cast<py::tuple>();
          StepResult step;
          step.terminated = parts[2].cast<bool>();
          step.truncated = !step.terminated && parts[3].cast<bool>();
          absl::Status written = WriteObservationAndMask(
              parts[0], parts[4], "step()", step.terminated || step.truncated,
              observation);
          if (!written.ok()) return written;
          step.reward = parts[1].cast<double>();
          if (!std::isfinite(step.reward)) {
            return absl::InvalidArgumentError(
                absl::StrCat(spec_.name, ": step() returned the reward ",
                             step.reward, ", which is not finite"));
          }
          return step;
        });
    if (!result.ok()) {
      // The episode's state is unknown after an error.
      needs_reset_ = true;
      return result.status();
    }
    if (result->terminated || result->truncated) needs_reset_ = true;
    return result;
  }

  absl::Status ActionMask(absl::Span<uint8_t> mask) const override {
    if (masks_ == MaskSource::kNone) return Environment::ActionMask(mask);
    if (needs_reset_) {
      return absl::FailedPreconditionError(
          absl::StrCat(spec_.name, ": no action mask before a reset"));
    }
    if (mask.size() != mask_.size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name, ": the mask holds ", mask_.size(), " entries"));
    }
    std::copy(mask_.begin(), mask_.end(), mask.begin());
    return absl::OkStatus();
  }

  absl::StatusOr<std::string> SaveState() const override {
    return WithPython<std::string>(
        spec_.name, "get_state()", [&]() -> absl::StatusOr<std::string> {
          if (!py::hasattr(env_, "get_state")) {
            return absl::UnimplementedError(absl::StrCat(
                spec_.name,
                " has no get_state() and set_state(); its episodes restart "
                "on resume"));
          }
          py::bytes pickled = py::module_::import("pickle").attr("dumps")(
              env_.attr("get_state")());
          StateWriter writer(kStateKind, kStateVersion);
          writer.PutBytes(spec_.name);
          writer.PutBool(needs_reset_);
          writer.PutBytes(std::string(pickled));
          // Only a masked env's: an unmasked one's state is as before.
          if (masks_ != MaskSource::kNone) {
            writer.PutBytes(std::string(mask_.begin(), mask_.end()));
          }
          return std::move(writer).Finish();
        });
  }

  absl::Status RestoreState(absl::string_view state) override {
    StateReader reader(state, kStateKind, kStateVersion,
                       absl::StrCat(spec_.name, ": state"));
    reader.ExpectEqual("the environment", reader.GetBytes("name"), spec_.name);
    const bool needs_reset = reader.GetBool("needs_reset");
    const std::string pickled(reader.GetBytes("get_state()"));
    std::vector<uint8_t> mask;
    if (masks_ != MaskSource::kNone) {
      const absl::string_view bytes = reader.GetBytes("action mask");
      mask.assign(bytes.begin(), bytes.end());
      reader.Check(needs_reset || CheckActionMask(spec_, mask).ok(),
                   "a bad action mask");
    }
    if (absl::Status status = reader.Finish(); !status.ok()) return status;
    absl::StatusOr<bool> restored = WithPython<bool>(
        spec_.name, "set_state()", [&]() -> absl::StatusOr<bool> {
          if (!py::hasattr(env_, "set_state")) {
            return absl::InvalidArgumentError(absl::StrCat(
                spec_.name, " has get_state() but no set_state()"));
          }
          env_.attr("set_state")(
              py::module_::import("pickle").attr("loads")(py::bytes(pickled)));
          return true;
        });
    if (!restored.ok()) return restored.status();
    needs_reset_ = needs_reset;
    if (masks_ != MaskSource::kNone) mask_ = std::move(mask);
    return absl::OkStatus();
  }

  absl::StatusOr<Frame> Render(int width, int height) override {
    if (width < 1 || height < 1) {
      return absl::InvalidArgumentError("a frame needs width, height >= 1");
    }
    return WithPython<Frame>(
        spec_.name, "render()", [&]() -> absl::StatusOr<Frame> {
          if (!py::hasattr(env_, "render")) {
            return absl::UnimplementedError(
                absl::StrCat(spec_.name, " has no render()"));
          }
          py::object image = env_.attr("render")();
          if (image.is_none()) {
            return absl::UnimplementedError(absl::StrCat(
                spec_.name,
                ": render() returned None (make the env with "
                "render_mode=\"rgb_array\", e.g. through --env_kwargs)"));
          }
          auto pixels = py::array_t<uint8_t, py::array::c_style>::ensure(image);
          if (!pixels || pixels.ndim() != 3 || pixels.shape(2) != 3) {
            return absl::InvalidArgumentError(absl::StrCat(
                spec_.name,
                ": render() must return an RGB array of height x width x 3 "
                "uint8 values"));
          }
          return Resized(pixels, width, height);
        });
  }

 private:
  PythonEnv() = default;

  // The spec from the spaces (GIL held).
  absl::StatusOr<bool> Describe() {
    py::module_& bridge = PythonBridge();
    py::tuple entries =
        bridge.attr("observation_entries")(env_.attr("observation_space"));
    py::list boxes = entries[1].cast<py::list>();
    if (py::len(boxes) == 1 && boxes[0].cast<py::tuple>()[1]
                                       .cast<py::tuple>()[0]
                                       .cast<std::string>() != "box") {
      return absl::InvalidArgumentError(
          absl::StrCat(spec_.name,
                       ": the observation space is Discrete; vantage takes box "
                       "observations (one-hot encode it into a Box)"));
    }
    bool mask_key = false;
    absl::StatusOr<PythonObservations> observations =
        PythonObservations::Describe(entries, spec_, mask_key);
    if (!observations.ok()) return observations.status();
    observations_ = *std::move(observations);
    if (mask_key) masks_ = MaskSource::kObservationKey;
    py::tuple action =
        bridge.attr("describe_space")(env_.attr("action_space"), "action");
    if (absl::Status status = DescribeActions(action); !status.ok()) {
      return status;
    }
    if (absl::Status status = DescribeMasks(); !status.ok()) return status;
    spec_.max_episode_steps =
        bridge.attr("max_episode_steps")(env_).cast<int64_t>();
    spec_.control_dt = 1.0 / 30;
    py::object metadata = py::getattr(env_, "metadata", py::none());
    if (py::isinstance<py::dict>(metadata) && metadata.contains("render_fps") &&
        !metadata["render_fps"].is_none()) {
      const double fps = metadata["render_fps"].cast<double>();
      if (fps > 0) spec_.control_dt = 1.0 / fps;
    }
    return true;
  }

  absl::Status DescribeActions(const py::tuple& space) {
    if (space[0].cast<std::string>() == "multidiscrete") {
      spec_.discrete = true;
      spec_.action_nvec = space[4].cast<std::vector<int64_t>>();
      action_shape_ = space[2].cast<std::vector<int64_t>>();
      action_dtype_ = py::dtype(space[3].cast<std::string>());
      spec_.action_size = 0;
      for (int64_t choices : spec_.action_nvec) {
        if (choices < 1) {
          return absl::InvalidArgumentError(
              absl::StrCat(spec_.name, ": the action space has a value of ",
                           choices, " choices"));
        }
        spec_.action_size += choices;
      }
      if (spec_.action_nvec.empty()) {
        return absl::InvalidArgumentError(
            absl::StrCat(spec_.name, ": the action space has no values"));
      }
      return absl::OkStatus();
    }
    if (space[0].cast<std::string>() == "discrete") {
      spec_.discrete = true;
      spec_.action_size = space[1].cast<int64_t>();
      if (spec_.action_size < 1) {
        return absl::InvalidArgumentError(
            absl::StrCat(spec_.name, ": the action space has no actions"));
      }
      return absl::OkStatus();
    }
    const std::string dtype = space[3].cast<std::string>();
    if (dtype.size() < 2 || dtype[1] != 'f') {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name, ": a box action space of dtype ", dtype,
          "; vantage's continuous actions are floats (use Discrete for a "
          "choice)"));
    }
    action_dtype_ = py::dtype(dtype);
    action_shape_ = space[2].cast<std::vector<int64_t>>();
    spec_.action_low = space[4].cast<std::vector<double>>();
    spec_.action_high = space[5].cast<std::vector<double>>();
    spec_.action_size = static_cast<int64_t>(spec_.action_low.size());
    for (int64_t i = 0; i < spec_.action_size; ++i) {
      if (!std::isfinite(spec_.action_low[i]) ||
          !std::isfinite(spec_.action_high[i]) ||
          spec_.action_low[i] > spec_.action_high[i]) {
        return absl::InvalidArgumentError(absl::StrCat(
            spec_.name, ": the action space's bounds at ", i, " are [",
            spec_.action_low[i], ", ", spec_.action_high[i],
            "]; vantage needs finite bounds"));
      }
    }
    if (spec_.action_size < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(spec_.name, ": the action space has no dimensions"));
    }
    return absl::OkStatus();
  }

  // Masks come with a Discrete action space, from an observation key or
  // from the info of every reset and step, which the first reset's says
  // (GIL held).
  absl::Status DescribeMasks() {
    if (masks_ == MaskSource::kObservationKey && !spec_.discrete) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name,
          ": the observation has an action_mask key, but the action space "
          "is not Discrete (masks choose among discrete actions)"));
    }
    if (masks_ == MaskSource::kNone && spec_.discrete &&
        PythonBridge().attr("first_info_has_action_mask")(env_).cast<bool>()) {
      masks_ = MaskSource::kInfo;
    }
    spec_.action_masks = masks_ != MaskSource::kNone;
    mask_.assign(spec_.action_masks ? spec_.action_size : 0, 0);
    return absl::OkStatus();
  }

  // The observation of a reset or step, and its mask where the env gives
  // them: `info` is that call's info (GIL held). An episode that ended
  // needs no mask (no action follows it).
  absl::Status WriteObservationAndMask(py::handle value, py::handle info,
                                       const char* call, bool ended,
                                       absl::Span<double> out) {
    py::handle observation = value;
    py::object mask;
    if (masks_ == MaskSource::kObservationKey) {
      if (!py::isinstance<py::dict>(value)) {
        return absl::InvalidArgumentError(absl::StrCat(
            spec_.name, ": ", call,
            " returned an observation that is not a dict, as its space "
            "says"));
      }
      py::dict parts = py::reinterpret_borrow<py::dict>(value);
      if (!parts.contains("action_mask")) {
        return absl::InvalidArgumentError(
            absl::StrCat(spec_.name, ": ", call,
                         " returned an observation without the action_mask "
                         "key its space has"));
      }
      mask = parts["action_mask"];
    } else if (masks_ == MaskSource::kInfo && py::isinstance<py::dict>(info) &&
               py::reinterpret_borrow<py::dict>(info).contains("action_mask")) {
      mask = py::reinterpret_borrow<py::dict>(info)["action_mask"];
    }
    if (absl::Status status = observations_.Write(observation, call, out);
        !status.ok()) {
      return status;
    }
    if (masks_ == MaskSource::kNone || ended) return absl::OkStatus();
    if (!mask) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name, ": ", call,
          "'s info has no action_mask (the first reset's had one, so every "
          "reset and step must)"));
    }
    return ReadMask(mask, call);
  }

  // `value` as the mask of the state just reached: a sequence of
  // action_size booleans (or 0/1 integers), one of them true (GIL held).
  absl::Status ReadMask(py::handle value, const char* call) {
    py::array array = py::array::ensure(value);
    const char kind = array ? array.dtype().kind() : '?';
    if (!array || array.ndim() != 1 ||
        std::string("biu").find(kind) == std::string::npos) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name, ": ", call,
          " gave an action_mask that is not a 1-D array of booleans"));
    }
    auto values =
        py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(
            array);
    std::vector<uint8_t> mask(values.size());
    for (size_t i = 0; i < mask.size(); ++i) {
      const int64_t v = values.data()[i];
      mask[i] = v == 0 || v == 1 ? static_cast<uint8_t>(v) : uint8_t{2};
    }
    if (absl::Status status = CheckActionMask(spec_, mask); !status.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat(status.message(), " (", call, "'s action_mask)"));
    }
    mask_ = std::move(mask);
    return absl::OkStatus();
  }

  // The action as the env takes it: an int, or an array of the space's
  // shape and dtype, clipped to its bounds (GIL held).
  py::object Action(absl::Span<const double> action) const {
    if (!spec_.action_nvec.empty()) {
      py::array_t<int64_t> values(action_shape_);
      for (size_t i = 0; i < action.size(); ++i) {
        values.mutable_data()[i] = static_cast<int64_t>(action[i]);
      }
      return values.attr("astype")(action_dtype_);
    }
    if (spec_.discrete) return py::int_(static_cast<int64_t>(action[0]));
    py::array out(action_dtype_, action_shape_);
    const size_t n = action.size();
    if (action_dtype_.itemsize() == 4) {
      auto* values = static_cast<float*>(out.mutable_data());
      for (size_t i = 0; i < n; ++i) {
        values[i] = static_cast<float>(
            std::clamp(action[i], spec_.action_low[i], spec_.action_high[i]));
      }
    } else if (action_dtype_.itemsize() == 8) {
      auto* values = static_cast<double*>(out.mutable_data());
      for (size_t i = 0; i < n; ++i) {
        values[i] =
            std::clamp(action[i], spec_.action_low[i], spec_.action_high[i]);
      }
    } else {
      py::array_t<double> wide(action_shape_);
      for (size_t i = 0; i < n; ++i) {
        wide.mutable_data()[i] =
            std::clamp(action[i], spec_.action_low[i], spec_.action_high[i]);
      }
      return wide.attr("astype")(action_dtype_);
    }
    return std::move(out);
  }

  // `pixels` (height x width x 3) scaled to width x height, nearest pixel.
  static Frame Resized(const py::array_t<uint8_t, py::array::c_style>& pixels,
                       int width, int height) {
    const int64_t in_h = pixels.shape(0), in_w = pixels.shape(1);
    Frame frame;
    frame.width = width;
    frame.height = height;
    frame.rgb.resize(static_cast<size_t>(3) * width * height);
    const uint8_t* in = pixels.data();
    for (int y = 0; y < height; ++y) {
      const int64_t sy = y * in_h / height;
      for (int x = 0; x < width; ++x) {
        const int64_t sx = x * in_w / width;
        std::memcpy(&frame.rgb[(static_cast<size_t>(y) * width + x) * 3],
                    in + (sy * in_w + sx) * 3, 3);
      }
    }
    return frame;
  }

  EnvSpec spec_;
  PythonObservations observations_;
  py::dtype action_dtype_ = py::dtype::of<float>();
  std::vector<int64_t> action_shape_;
  py::object env_;
  py::object reset_;
  py::object step_;
  bool needs_reset_ = true;
  // Where the env's action masks come from, and the current state's.
  enum class MaskSource { kNone, kObservationKey, kInfo };
  MaskSource masks_ = MaskSource::kNone;
  std::vector<uint8_t> mask_;
};

}  // namespace

bool IsPythonEnvName(absl::string_view name) {
  return absl::StartsWith(name, "python:") || absl::StartsWith(name, "gym:");
}

absl::StatusOr<std::unique_ptr<Environment>> MakePythonEnv(
    absl::string_view name, const std::string& kwargs_json) {
  const std::string target(name);
  absl::string_view rest = name;
  if (absl::ConsumePrefix(&rest, "python:")) {
    const size_t colon = rest.rfind(':');
    if (colon == absl::string_view::npos || colon == 0 ||
        colon + 1 == rest.size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "'", name,
          "' names no factory: use python:MODULE:CALLABLE (MODULE an "
          "importable module or a .py file)"));
    }
  } else if (absl::ConsumePrefix(&rest, "gym:") && rest.empty()) {
    return absl::InvalidArgumentError("gym: needs an id, e.g. gym:CartPole-v1");
  }
  return PythonEnv::Create(target, kwargs_json);
}

absl::StatusOr<double> PlainPythonStepsPerSecond(
    absl::string_view name, const std::string& kwargs_json,
    const std::vector<double>& action, int64_t steps) {
  EnsurePythonInterpreter();
  const std::string target(name);
  return WithPython<double>(target, "plain Python loop", [&] {
    py::object env = PythonBridge().attr("make")(target, kwargs_json);
    const double rate =
        PythonBridge().attr("plain_loop")(env, action, steps).cast<double>();
    if (py::hasattr(env, "close")) env.attr("close")();
    return rate;
  });
}

}  // namespace vantage
