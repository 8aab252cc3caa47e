#include "common/env/environment.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace vantage {

std::string EnvSpec::ActionString() const {
  return absl::StrCat(discrete ? "discrete:" : "continuous:", action_size);
}

absl::StatusOr<std::string> Environment::SaveState() const {
  return absl::UnimplementedError(
      absl::StrCat(spec().name, ": this environment cannot save its state"));
}

absl::Status Environment::RestoreState(absl::string_view) {
  return absl::UnimplementedError(absl::StrCat(
      spec().name, ": this environment cannot restore a saved state"));
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
  if (observation.size() != static_cast<size_t>(spec.observation_size)) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec.name, ": observation buffer holds ", observation.size(),
        " values, expected ", spec.observation_size));
  }
  return absl::OkStatus();
}

}  // namespace vantage
