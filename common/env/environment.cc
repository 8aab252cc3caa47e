#include "common/env/environment.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace vantage {

std::string EnvSpec::ActionString() const {
  return absl::StrCat(discrete ? "discrete:" : "continuous:", action_size,
                      action_masks ? " masked" : "");
}

std::string EnvSpec::ObservationString() const {
  if (observation_shape.empty()) return absl::StrCat(observation_size);
  return absl::StrCat(byte_observations() ? "uint8 " : "",
                      absl::StrJoin(observation_shape, "x"));
}

absl::StatusOr<std::string> Environment::SaveState() const {
  return absl::UnimplementedError(
      absl::StrCat(spec().name, ": this environment cannot save its state"));
}

absl::Status Environment::RestoreState(absl::string_view) {
  return absl::UnimplementedError(absl::StrCat(
      spec().name, ": this environment cannot restore a saved state"));
}

absl::Status Environment::ActionMask(absl::Span<uint8_t>) const {
  return absl::UnimplementedError(
      absl::StrCat(spec().name, ": this environment has no action masks"));
}

absl::StatusOr<Frame> Environment::Render(int, int) {
  return absl::UnimplementedError(
      absl::StrCat(spec().name, ": this environment cannot render"));
}

absl::Status CheckAction(const EnvSpec& spec, absl::Span<const double> action) {
  const size_t expected = spec.discrete ? 1 : spec.action_size;
  if (action.size() != expected) {
    return absl::InvalidArgumentError(
        absl::StrCat(spec.name, ": action has ", action.size(),
                     " values, expected ", expected));
  }
  for (size_t i = 0; i < action.size(); ++i) {
    if (!std::isfinite(action[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec.name, ": action[", i, "] is not finite (", action[i], ")"));
    }
  }
  if (spec.discrete && (action[0] != std::floor(action[0]) || action[0] < 0 ||
                        action[0] >= static_cast<double>(spec.action_size))) {
    return absl::InvalidArgumentError(
        absl::StrCat(spec.name, ": discrete action ", action[0],
                     " is not an integer in [0, ", spec.action_size, ")"));
  }
  return absl::OkStatus();
}

absl::Status CheckActionMask(const EnvSpec& spec,
                             absl::Span<const uint8_t> mask) {
  if (!spec.action_masks || !spec.discrete) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec.name, ": an action mask for ", spec.ActionString(),
        " actions, which take none (only masked discrete actions do)"));
  }
  if (mask.size() != static_cast<size_t>(spec.action_size)) {
    return absl::InvalidArgumentError(
        absl::StrCat(spec.name, ": the action mask has ", mask.size(),
                     " entries, expected ", spec.action_size));
  }
  bool any_legal = false;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i] > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(spec.name, ": action mask entry ", i, " is ",
                       static_cast<int>(mask[i]), ", expected 0 or 1"));
    }
    any_legal = any_legal || mask[i] == 1;
  }
  if (!any_legal) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec.name, ": the action mask is all zero (no legal action)"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<uint8_t>> ReadActionMask(const Environment& env) {
  const EnvSpec& spec = env.spec();
  if (!spec.action_masks) return std::vector<uint8_t>();
  std::vector<uint8_t> mask(spec.action_size);
  if (absl::Status status = env.ActionMask(absl::MakeSpan(mask));
      !status.ok()) {
    return status;
  }
  if (absl::Status status = CheckActionMask(spec, mask); !status.ok()) {
    return status;
  }
  return mask;
}

absl::Status CheckStep(const EnvSpec& spec, bool needs_reset,
                       absl::Span<const double> action,
                       absl::Span<double> observation) {
  if (needs_reset) {
    return absl::FailedPreconditionError(
        absl::StrCat(spec.name, ": Reset before stepping"));
  }
  if (absl::Status status = CheckAction(spec, action); !status.ok()) {
    return status;
  }
  return CheckObservationBuffer(spec, observation);
}

absl::Status CheckObservationLayout(const EnvSpec& spec) {
  if (spec.observation_high < 0 || spec.observation_high > 255) {
    return absl::InvalidArgumentError(
        absl::StrCat("spec.observation_high: ", spec.observation_high,
                     ", expected 0 (real values) or 1..255 (bytes)"));
  }
  if (spec.observation_shape.empty()) return absl::OkStatus();
  const std::string shape = absl::StrJoin(spec.observation_shape, "x");
  if (spec.observation_shape.size() != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("spec.observation_shape: ", shape,
                     ", expected [channels, height, width] or nothing"));
  }
  int64_t product = 1;
  for (int64_t dimension : spec.observation_shape) {
    // Each bounded before multiplying, so the product cannot overflow.
    if (dimension < 1 || dimension > spec.observation_size) {
      return absl::InvalidArgumentError(
          absl::StrCat("spec.observation_shape: ", shape,
                       ", expected dimensions in [1, observation_size ",
                       spec.observation_size, "]"));
    }
    product *= dimension;
    if (product > spec.observation_size) break;
  }
  if (product != spec.observation_size) {
    return absl::InvalidArgumentError(absl::StrCat(
        "spec.observation_shape: ", shape, " holds ",
        product > spec.observation_size ? "more than " : "", product,
        " values, expected observation_size ", spec.observation_size));
  }
  return absl::OkStatus();
}

absl::Status CheckObservationBuffer(const EnvSpec& spec,
                                    absl::Span<double> observation) {
  if (observation.size() != static_cast<size_t>(spec.observation_size)) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec.name, ": observation buffer holds ", observation.size(),
        " values, expected ", spec.observation_size));
  }
  return absl::OkStatus();
}

}  // namespace vantage
