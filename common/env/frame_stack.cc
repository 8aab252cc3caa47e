#include "common/env/frame_stack.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "frame_stack";
constexpr uint32_t kStateVersion = 1;

// What an inner environment can have written: finite, and for byte
// observations an integer in [0, observation_high].
bool PlausibleObservation(const EnvSpec& spec, double value) {
  if (!std::isfinite(value)) return false;
  if (!spec.byte_observations()) return true;
  return value >= 0 && value <= static_cast<double>(spec.observation_high) &&
         value == std::floor(value);
}

}  // namespace

EnvSpec StackedSpec(const EnvSpec& spec, int64_t frames) {
  EnvSpec stacked = spec;
  if (frames <= 1) return stacked;
  stacked.observation_size = spec.observation_size * frames;
  if (!stacked.observation_shape.empty()) {
    stacked.observation_shape[0] *= frames;
  }
  return stacked;
}

absl::StatusOr<std::unique_ptr<Environment>> FrameStack::Wrap(
    std::unique_ptr<Environment> inner, int64_t frames) {
  if (frames < 2 || frames > kMaxFrameStack) {
    return absl::InvalidArgumentError(
        absl::StrCat("frame_stack: ", frames, " frames, expected 2..",
                     kMaxFrameStack, " (1: no stacking)"));
  }
  if (!inner->spec().observation_keys.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "frame_stack: ", inner->spec().name,
        " has a Dict observation, which vantage does not stack (stack "
        "inside the environment, or use a recurrent --core)"));
  }
  return std::unique_ptr<Environment>(new FrameStack(std::move(inner), frames));
}

FrameStack::FrameStack(std::unique_ptr<Environment> inner, int64_t frames)
    : EnvironmentWrapper(std::move(inner)),
      frames_(frames),
      spec_(StackedSpec(this->inner().spec(), frames)),
      history_(static_cast<size_t>(spec_.observation_size), 0.0),
      latest_(static_cast<size_t>(this->inner().spec().observation_size), 0.0) {
}

void FrameStack::Push() {
  std::copy(history_.begin() + latest_.size(), history_.end(),
            history_.begin());
  std::copy(latest_.begin(), latest_.end(), history_.end() - latest_.size());
}

void FrameStack::Write(absl::Span<double> observation) const {
  std::copy(history_.begin(), history_.end(), observation.begin());
}

absl::Status FrameStack::Reset(uint64_t seed, absl::Span<double> observation) {
  if (absl::Status status = CheckObservationBuffer(spec_, observation);
      !status.ok()) {
    return status;
  }
  if (absl::Status status =
          mutable_inner().Reset(seed, absl::MakeSpan(latest_));
      !status.ok()) {
    return status;
  }
  for (int64_t i = 0; i < frames_; ++i) Push();
  Write(observation);
  return absl::OkStatus();
}

absl::StatusOr<StepResult> FrameStack::Step(absl::Span<const double> action,
                                            absl::Span<double> observation) {
  if (absl::Status status = CheckObservationBuffer(spec_, observation);
      !status.ok()) {
    return status;
  }
  absl::StatusOr<StepResult> result =
      mutable_inner().Step(action, absl::MakeSpan(latest_));
  if (!result.ok()) return result;
  Push();
  Write(observation);
  return result;
}

absl::StatusOr<std::string> FrameStack::SaveState() const {
  absl::StatusOr<std::string> inner_state = inner().SaveState();
  if (!inner_state.ok()) return inner_state.status();
  StateWriter writer(kStateKind, kStateVersion);
  writer.PutBytes(spec_.name);
  writer.PutI64(frames_);
  writer.PutI64(inner().spec().observation_size);
  writer.PutDoubles(history_);
  writer.PutBytes(*inner_state);
  return std::move(writer).Finish();
}

absl::Status FrameStack::RestoreState(absl::string_view state) {
  StateReader reader(state, kStateKind, kStateVersion,
                     absl::StrCat(spec_.name, ": frame stack state"));
  reader.ExpectEqual("the environment", reader.GetBytes("name"), spec_.name);
  reader.ExpectEqual("frames", reader.GetI64("frames"), frames_);
  reader.ExpectEqual("observation_size", reader.GetI64("observation_size"),
                     inner().spec().observation_size);
  std::vector<double> history = reader.GetDoubles("history", history_.size());
  const EnvSpec& inner_spec = inner().spec();
  reader.Check(std::all_of(history.begin(), history.end(),
                           [&](double value) {
                             return PlausibleObservation(inner_spec, value);
                           }),
               "history holds a value no observation can have");
  const absl::string_view inner_state = reader.GetBytes("inner state");
  if (absl::Status status = reader.Finish(); !status.ok()) return status;
  // The inner environment restores all or nothing, so nothing has changed
  // if it fails.
  if (absl::Status status = mutable_inner().RestoreState(inner_state);
      !status.ok()) {
    return status;
  }
  history_ = std::move(history);
  return absl::OkStatus();
}

}  // namespace vantage
