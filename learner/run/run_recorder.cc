#include "learner/run/run_recorder.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace vantage {

RunRecorder::RunRecorder(std::optional<RunDirectory> run, RecorderConfig config)
    : run_(std::move(run)),
      config_(std::move(config)),
      start_(std::chrono::steady_clock::now()) {}

double RunRecorder::Seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start_)
      .count();
}

absl::StatusOr<ProgressRow> RunRecorder::Record(
    const LearnerCore& learner, const UpdateStats& stats,
    absl::FunctionRef<absl::StatusOr<CheckpointExtras>()> extras) {
  ProgressRow row;
  row.stats = stats;
  row.mean_return = stats.mean_return;
  const double seconds = Seconds();
  row.elapsed_seconds = config_.elapsed_before + seconds;
  row.steps_per_second =
      (stats.env_steps - config_.steps_before) / std::max(seconds, 1e-9);
  if (!run_.has_value()) return row;
  if (absl::Status status = run_->AppendProgress(row); !status.ok()) {
    return status;
  }
  const bool last = stats.env_steps >= config_.total_env_steps;
  if (!last && stats.policy_version % config_.recording.checkpoint_every != 0)
    return row;
  if (absl::Status status =
          WriteRunCheckpoint(learner, row.elapsed_seconds, extras);
      !status.ok()) {
    return status;
  }
  return row;
}

absl::Status RunRecorder::CheckpointNow(
    const LearnerCore& learner,
    absl::FunctionRef<absl::StatusOr<CheckpointExtras>()> extras) {
  if (!run_.has_value() || learner.env_steps() == config_.steps_before ||
      learner.policy_version() == checkpointed_version_) {
    return absl::OkStatus();
  }
  return WriteRunCheckpoint(learner, config_.elapsed_before + Seconds(),
                            extras);
}

absl::Status RunRecorder::WriteRunCheckpoint(
    const LearnerCore& learner, double elapsed_seconds,
    absl::FunctionRef<absl::StatusOr<CheckpointExtras>()> extras) {
  absl::StatusOr<CheckpointExtras> all = extras();
  if (!all.ok()) return all.status();
  (*all)[kCheckpointConfig] = config_.recording.config_json;
  (*all)[kCheckpointElapsed] = absl::StrCat(elapsed_seconds);
  if (absl::Status status =
          WriteCheckpoint(CheckpointPath(run_->checkpoint_directory(),
                                         learner.policy_version()),
                          learner, *all);
      !status.ok()) {
    return status;
  }
  checkpointed_version_ = learner.policy_version();
  return PruneCheckpoints(run_->checkpoint_directory(),
                          config_.recording.keep_checkpoints);
}

}  // namespace vantage
