#include "learner/run/run_recorder.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "absl/strings/str_cat.h"

namespace vantage {

RunRecorder::RunRecorder(std::optional<RunDirectory> run, RecorderConfig config)
    : run_(std::move(run)),
      config_(std::move(config)),
      start_(std::chrono::steady_clock::now()) {}

absl::Status RunRecorder::EvaluateEvery(int64_t every) {
  eval_every_ = every;
  if (!run_.has_value() || every <= 0) return absl::OkStatus();
  absl::StatusOr<BestCheckpoint> best =
      BestCheckpoint::Open(run_->checkpoint_directory());
  if (!best.ok()) return best.status();
  best_ = *std::move(best);
  return absl::OkStatus();
}

double RunRecorder::Seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start_)
      .count();
}

bool RunRecorder::Evaluates(int64_t version) const {
  return eval_every_ > 0 && version % eval_every_ == 0;
}

absl::StatusOr<ProgressRow> RunRecorder::Record(
    const LearnerCore& learner, const UpdateStats& stats,
    const std::vector<PolicyEvaluation>& evaluations,
    absl::FunctionRef<absl::StatusOr<CheckpointExtras>()> extras) {
  ProgressRow row;
  row.stats = stats;
  row.mean_return = stats.mean_return;
  const double seconds = Seconds();
  row.elapsed_seconds = config_.elapsed_before + seconds;
  row.steps_per_second =
      (stats.env_steps - config_.steps_before) / std::max(seconds, 1e-9);
  if (!evaluations.empty()) row.evaluation = Summarize(evaluations.back());
  if (!run_.has_value()) return row;
  if (absl::Status status = run_->AppendProgress(row); !status.ok()) {
    return status;
  }
  const bool last = stats.env_steps >= config_.total_env_steps;
  const int64_t version = stats.policy_version;
  if (last || version % config_.recording.checkpoint_every == 0 ||
      Evaluates(version)) {
    if (absl::Status status =
            WriteRunCheckpoint(learner, row.elapsed_seconds, extras);
        !status.ok()) {
      return status;
    }
  }
  if (Evaluates(version) && best_.has_value()) {
    if (absl::Status status = best_->Hold(
            CheckpointPath(run_->checkpoint_directory(), version), version);
        !status.ok()) {
      return status;
    }
  }
  if (absl::Status status = OfferToBest(evaluations); !status.ok()) {
    return status;
  }
  return row;
}

absl::Status RunRecorder::OfferToBest(
    const std::vector<PolicyEvaluation>& evaluations) {
  if (!best_.has_value()) return absl::OkStatus();
  for (const PolicyEvaluation& evaluation : evaluations) {
    absl::StatusOr<bool> kept = best_->Offer(Summarize(evaluation));
    // An evaluation of a version checkpointed by an earlier life of the
    // run (resumed since) has nothing held: it is recorded, not kept.
    if (absl::IsNotFound(kept.status())) {
      std::fprintf(stderr, "learner: %s\n",
                   std::string(kept.status().message()).c_str());
      continue;
    }
    if (!kept.ok()) return kept.status();
  }
  return absl::OkStatus();
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
