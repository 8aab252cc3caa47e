#include "common/rollout/segment.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace vantage {
namespace {

std::string Shape(const at::Tensor& t) {
  return absl::StrCat("[", absl::StrJoin(t.sizes(), ", "), "]");
}

// `max_abs` bounds the magnitude of float32 and uint8 fields (infinite:
// none).
absl::Status Expect(const at::Tensor& t, const char* field,
                    std::vector<int64_t> shape, at::ScalarType dtype,
                    double max_abs = std::numeric_limits<double>::infinity()) {
  if (!t.defined()) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment field ", field, " is missing"));
  }
  if (t.sizes() != at::IntArrayRef(shape)) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment field ", field, " has shape ", Shape(t),
                     ", expected [", absl::StrJoin(shape, ", "), "]"));
  }
  if (t.scalar_type() != dtype) {
    return absl::InvalidArgumentError(absl::StrCat(
        "segment field ", field, " has dtype ", at::toString(t.scalar_type()),
        ", expected ", at::toString(dtype)));
  }
  // Plain loops: a segment is small, and a few tensor ops per field would
  // cost more than the data (this runs for every segment a learner takes).
  if (dtype == at::kFloat) {
    const at::Tensor dense = t.contiguous();
    const float* values = dense.data_ptr<float>();
    for (int64_t i = 0, n = dense.numel(); i < n; ++i) {
      if (!std::isfinite(values[i])) {
        return absl::InvalidArgumentError(
            absl::StrCat("segment field ", field, " holds non-finite values"));
      }
      if (std::fabs(values[i]) > max_abs) {
        return absl::InvalidArgumentError(absl::StrCat(
            "segment field ", field, " holds ", values[i], " at element ", i,
            ", beyond the limit of +-", max_abs));
      }
    }
  }
  if (dtype == at::kByte) {
    const at::Tensor dense = t.contiguous();
    const uint8_t* values = dense.data_ptr<uint8_t>();
    for (int64_t i = 0, n = dense.numel(); i < n; ++i) {
      if (values[i] > max_abs) {
        return absl::InvalidArgumentError(
            absl::StrCat("segment field ", field, " holds ",
                         static_cast<int>(values[i]), " at element ", i,
                         ", above the env's observation_high of ", max_abs));
      }
    }
  }
  return absl::OkStatus();
}

// The number of set flags, and whether any step has both.
int64_t CountSet(const at::Tensor& flags) {
  const at::Tensor dense = flags.contiguous();
  const bool* values = dense.data_ptr<bool>();
  int64_t count = 0;
  for (int64_t i = 0, n = dense.numel(); i < n; ++i) count += values[i];
  return count;
}

bool AnyBoth(const at::Tensor& a, const at::Tensor& b) {
  const at::Tensor dense_a = a.contiguous();
  const at::Tensor dense_b = b.contiguous();
  const bool* x = dense_a.data_ptr<bool>();
  const bool* y = dense_b.data_ptr<bool>();
  for (int64_t i = 0, n = dense_a.numel(); i < n; ++i) {
    if (x[i] && y[i]) return true;
  }
  return false;
}

// Step 0's place in its episode, within the spec's time limit.
absl::Status CheckFirstEpisodeStep(const Segment& segment,
                                   const EnvSpec& spec) {
  if (segment.first_episode_step < 0 ||
      (spec.max_episode_steps > 0 &&
       segment.first_episode_step >= spec.max_episode_steps)) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment field first_episode_step is ",
                     segment.first_episode_step, ", expected ",
                     spec.max_episode_steps > 0
                         ? absl::StrCat("0..", spec.max_episode_steps - 1)
                         : std::string(">= 0")));
  }
  return absl::OkStatus();
}

// The episodes a segment reports against the episode ends it holds.
absl::Status CheckEpisodes(const Segment& segment, const EnvSpec& spec,
                           const ValueLimits& limits) {
  if (absl::Status status = CheckFirstEpisodeStep(segment, spec);
      !status.ok()) {
    return status;
  }
  const size_t reported = segment.episode_returns.size();
  if (reported != segment.episode_lengths.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment lists ", reported, " episode returns but ",
                     segment.episode_lengths.size(), " episode lengths"));
  }
  const at::Tensor terminated = segment.terminated.contiguous();
  const at::Tensor truncated = segment.truncated.contiguous();
  const bool* term = terminated.data_ptr<bool>();
  const bool* trunc = truncated.data_ptr<bool>();
  size_t episode = 0;
  int64_t previous_end = -1;
  for (int64_t t = 0, n = segment.steps(); t < n; ++t) {
    if (!term[t] && !trunc[t]) continue;
    if (episode >= reported) {
      return absl::InvalidArgumentError(absl::StrCat(
          "segment reports ", reported, " episodes but ends one at step ", t));
    }
    const int64_t length = segment.episode_lengths[episode];
    const double value = segment.episode_returns[episode];
    // A failed env step (an env error) is not counted in its episode's
    // length, so a length may fall short of the steps between two ends.
    const int64_t at_most = previous_end < 0
                                ? std::numeric_limits<int64_t>::max()
                                : t - previous_end;
    if (length < 1 || length > at_most ||
        (spec.max_episode_steps > 0 && length > spec.max_episode_steps)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "segment field episode_lengths[", episode, "] is ", length,
          " for the episode ending at step ", t, ", expected 1..",
          std::min(at_most, spec.max_episode_steps > 0
                                ? spec.max_episode_steps
                                : std::numeric_limits<int64_t>::max())));
    }
    if (!std::isfinite(value) ||
        std::fabs(value) >
            limits.max_abs_reward * static_cast<double>(length)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "segment field episode_returns[", episode, "] is ", value,
          ", expected a finite return within +-max_abs_reward (",
          limits.max_abs_reward, ") per step of its ", length, " steps"));
    }
    previous_end = t;
    ++episode;
  }
  if (episode != reported) {
    return absl::InvalidArgumentError(absl::StrCat(
        "segment reports ", reported, " episodes but ends ", episode));
  }
  return absl::OkStatus();
}

// A recurrent policy's start state, of the run's size; none otherwise.
// A recurrent run takes whole segments: then every rollout starts where a
// segment does, with the state the segment carries.
absl::Status CheckCoreState(const Segment& segment, int64_t size,
                            int64_t max_steps, const ValueLimits& limits) {
  if (size == 0) {
    if (!segment.core_state.defined()) return absl::OkStatus();
    return absl::InvalidArgumentError(
        "segment field core_state is set, but this run's policy has no "
        "recurrent core (--core=none)");
  }
  if (!segment.core_state.defined()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "segment field core_state is missing: this run's policy is recurrent "
        "(a state of ",
        size,
        " floats per segment; an actor too old to send it cannot "
        "serve this run)"));
  }
  if (segment.steps() != max_steps) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment has ", segment.steps(),
                     " steps; a recurrent run takes whole "
                     "segments of ",
                     max_steps,
                     " (its core_state is the state at their "
                     "start)"));
  }
  return Expect(segment.core_state, "core_state", {size}, at::kFloat,
                limits.max_abs_observation);
}

// Masked discrete actions' masks: one row per step, each with a legal
// action, the one taken among them; none for any other run.
absl::Status CheckActionMasks(const Segment& segment, const EnvSpec& spec) {
  if (!spec.action_masks) {
    if (!segment.action_masks.defined()) return absl::OkStatus();
    return absl::InvalidArgumentError(absl::StrCat(
        "segment field action_masks is set, but this run's actions (",
        spec.ActionString(), ") take no masks"));
  }
  const int64_t steps = segment.steps();
  if (absl::Status status = Expect(segment.action_masks, "action_masks",
                                   {steps, spec.action_size}, at::kBool);
      !status.ok()) {
    return status;
  }
  const at::Tensor masks = segment.action_masks.contiguous();
  const at::Tensor actions = segment.actions.contiguous();
  const std::vector<int64_t> heads = spec.action_heads();
  const bool* row = masks.data_ptr<bool>();
  const float* action = actions.data_ptr<float>();
  for (int64_t t = 0; t < steps; ++t) {
    for (size_t h = 0; h < heads.size(); row += heads[h], ++h, ++action) {
      const std::string value =
          heads.size() > 1 ? absl::StrCat(" (value ", h, ")") : "";
      if (std::none_of(row, row + heads[h], [](bool legal) { return legal; })) {
        return absl::InvalidArgumentError(
            absl::StrCat("segment field action_masks is all zero at step ", t,
                         value, " (no legal action)"));
      }
      const int64_t taken = static_cast<int64_t>(*action);
      if (!row[taken]) {
        return absl::InvalidArgumentError(absl::StrCat(
            "segment field actions holds ", taken, " at step ", t, value,
            ", which that step's action mask makes illegal"));
      }
    }
  }
  return absl::OkStatus();
}

// Discrete actions are indices in range, legal under their masks if the
// run has masks.
absl::Status CheckDiscreteActions(const Segment& segment, const EnvSpec& spec) {
  if (spec.discrete) {
    const at::Tensor a = segment.actions;
    const at::Tensor choices =
        at::tensor(spec.action_heads(), at::kLong).to(a.scalar_type());
    if (!(a == a.floor()).all().item<bool>() || (a < 0).any().item<bool>() ||
        (a >= choices).any().item<bool>()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "segment field actions holds values that are not action indices "
          "in [0, ",
          absl::StrJoin(spec.action_heads(), "), [0, "), ")"));
    }
  }
  return CheckActionMasks(segment, spec);
}

}  // namespace

absl::Status ValidateSegment(const Segment& segment, const EnvSpec& spec,
                             int64_t max_steps, const ValueLimits& limits,
                             int64_t core_state_size) {
  const int64_t steps = segment.steps();
  if (steps < 1 || steps > max_steps) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment has ", steps, " steps, expected 1..", max_steps));
  }
  const int64_t obs = spec.observation_size;
  const at::ScalarType observation_dtype =
      spec.byte_observations() ? at::kByte : at::kFloat;
  const double max_abs_observation =
      spec.byte_observations() ? static_cast<double>(spec.observation_high)
                               : limits.max_abs_observation;
  const int64_t act = spec.action_width();
  const int64_t truncations =
      segment.truncated.defined() && segment.truncated.numel() == steps &&
              segment.truncated.scalar_type() == at::kBool
          ? CountSet(segment.truncated)
          : -1;
  for (absl::Status status : {
           Expect(segment.rewards, "rewards", {steps}, at::kFloat,
                  limits.max_abs_reward),
           Expect(segment.observations, "observations", {steps + 1, obs},
                  observation_dtype, max_abs_observation),
           Expect(segment.actions, "actions", {steps, act}, at::kFloat,
                  limits.max_abs_action),
           Expect(segment.terminated, "terminated", {steps}, at::kBool),
           Expect(segment.truncated, "truncated", {steps}, at::kBool),
           Expect(segment.behaviour_log_probs, "behaviour_log_probs", {steps},
                  at::kFloat, limits.max_abs_log_prob),
       }) {
    if (!status.ok()) return status;
  }
  if (absl::Status status =
          Expect(segment.final_observations, "final_observations",
                 {truncations, obs}, observation_dtype, max_abs_observation);
      !status.ok()) {
    return status;
  }
  if (absl::Status status = CheckDiscreteActions(segment, spec); !status.ok()) {
    return status;
  }
  if (AnyBoth(segment.terminated, segment.truncated)) {
    return absl::InvalidArgumentError(
        "segment marks a step both terminated and truncated");
  }
  if (absl::Status status =
          CheckCoreState(segment, core_state_size, max_steps, limits);
      !status.ok()) {
    return status;
  }
  return CheckEpisodes(segment, spec, limits);
}

}  // namespace vantage
