#include "common/env/time_limit.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "time_limit";
constexpr uint32_t kStateVersion = 1;

}  // namespace

TimeLimit::TimeLimit(std::unique_ptr<Environment> inner)
    : EnvironmentWrapper(std::move(inner)) {}

absl::Status TimeLimit::Reset(uint64_t seed, absl::Span<double> observation) {
  running_ = false;
  elapsed_steps_ = 0;
  if (absl::Status status = mutable_inner().Reset(seed, observation);
      !status.ok()) {
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
  absl::StatusOr<StepResult> result = mutable_inner().Step(action, observation);
  if (!result.ok()) return result;
  ++elapsed_steps_;
  const int64_t limit = spec().max_episode_steps;
  if (!result->terminated && limit > 0 && elapsed_steps_ >= limit) {
    result->truncated = true;
  }
  if (result->terminated || result->truncated) running_ = false;
  return result;
}

absl::StatusOr<std::string> TimeLimit::SaveState() const {
  absl::StatusOr<std::string> inner_state = inner().SaveState();
  if (!inner_state.ok()) return inner_state.status();
  StateWriter writer(kStateKind, kStateVersion);
  writer.PutBytes(spec().name);
  writer.PutI64(spec().max_episode_steps);
  writer.PutI64(elapsed_steps_);
  writer.PutBool(running_);
  writer.PutBytes(*inner_state);
  return std::move(writer).Finish();
}

absl::Status TimeLimit::RestoreState(absl::string_view state) {
  StateReader reader(state, kStateKind, kStateVersion,
                     absl::StrCat(spec().name, ": time limit state"));
  reader.ExpectEqual("the environment", reader.GetBytes("name"), spec().name);
  const int64_t limit = spec().max_episode_steps;
  reader.ExpectEqual("max_episode_steps", reader.GetI64("max_episode_steps"),
                     limit);
  const int64_t elapsed = reader.GetI64("elapsed_steps");
  const bool running = reader.GetBool("running");
  const absl::string_view inner_state = reader.GetBytes("inner state");
  // A running episode has not reached the limit yet; an ended one may have.
  reader.Check(elapsed >= 0 && (limit <= 0 ||
                                (running ? elapsed < limit : elapsed <= limit)),
               absl::StrCat("elapsed_steps ", elapsed,
                            " is impossible with the limit ", limit));
  if (absl::Status status = reader.Finish(); !status.ok()) return status;
  // The inner environment restores all or nothing, so nothing has changed
  // if it fails.
  if (absl::Status status = mutable_inner().RestoreState(inner_state);
      !status.ok()) {
    return status;
  }
  elapsed_steps_ = elapsed;
  running_ = running;
  return absl::OkStatus();
}

}  // namespace vantage
