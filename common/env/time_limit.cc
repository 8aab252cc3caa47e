#include "common/env/time_limit.h"

#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {

TimeLimit::TimeLimit(std::unique_ptr<Environment> inner)
    : inner_(std::move(inner)) {}

absl::Status TimeLimit::Reset(uint64_t seed, absl::Span<double> observation) {
  running_ = false;
  elapsed_steps_ = 0;
  if (absl::Status status = inner_->Reset(seed, observation); !status.ok()) {
    return status;
  }
  running_ = true;
  return absl::OkStatus();
}

absl::StatusOr<StepResult> TimeLimit::Step(absl::Span<const double> action,
                                           absl::Span<double> observation) {
  if (!running_) {
    return absl::FailedPreconditionError(
        absl::StrCat(spec().name,
                     ": Step called before Reset or after the "
                     "episode ended"));
  }
  absl::StatusOr<StepResult> result = inner_->Step(action, observation);
  if (!result.ok()) return result;
  ++elapsed_steps_;
  const int64_t limit = spec().max_episode_steps;
  if (!result->terminated && limit > 0 && elapsed_steps_ >= limit) {
    result->truncated = true;
  }
  if (result->terminated || result->truncated) running_ = false;
  return result;
}

}  // namespace vantage
