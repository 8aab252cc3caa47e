#ifndef VANTAGE_LEARNER_RUN_RUN_RECORDER_H_
#define VANTAGE_LEARNER_RUN_RUN_RECORDER_H_

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/functional/function_ref.h"
#include "absl/status/statusor.h"
#include "common/rollout/policy_evaluation.h"
#include "learner/checkpoint/checkpoint.h"
#include "learner/learner_core.h"
#include "learner/run/best_checkpoint.h"
#include "learner/run/recording_config.h"
#include "learner/run/run_directory.h"

namespace vantage {

// Extras every run checkpoint carries besides the caller's.
inline constexpr char kCheckpointConfig[] = "config";
inline constexpr char kCheckpointElapsed[] = "elapsed_seconds";

struct RecorderConfig {
  RecordingConfig recording;  // its run_dir is the RunDirectory given
  int64_t total_env_steps = 0;
  // Where a resumed run starts: its elapsed time and env steps so far.
  double elapsed_before = 0.0;
  int64_t steps_before = 0;
};

// Records a training run as it goes: a progress row per update, appended to
// progress.csv, and a checkpoint every `checkpoint_every` updates, at every
// evaluated version and at the end (when there is a run directory), plus
// the wall-clock figures and the best-evaluated checkpoint.
class RunRecorder {
 public:
  RunRecorder(std::optional<RunDirectory> run, RecorderConfig config);

  // The run evaluates every `every` updates: those versions are
  // checkpointed and held until their evaluation, which keeps
  // checkpoints/best.pt (with a run directory).
  absl::Status EvaluateEvery(int64_t every);

  // `extras` adds the caller's byte strings to the checkpoint (e.g. the
  // local actor's state); it is called only when one is written.
  // `evaluations` finished since the last row (the newest goes into the
  // row; each is offered to the best checkpoint, after this version's
  // checkpoint is written and held if it is to be evaluated).
  absl::StatusOr<ProgressRow> Record(
      const LearnerCore& learner, const UpdateStats& stats,
      const std::vector<PolicyEvaluation>& evaluations,
      absl::FunctionRef<absl::StatusOr<CheckpointExtras>()> extras);

  // A checkpoint of the learner as it is now, unless its version already
  // has one, it has not updated since the run (re)started, or there is no
  // run directory: a run stopped between its
  // regular checkpoints (SIGTERM from a scheduler) loses no update.
  absl::Status CheckpointNow(
      const LearnerCore& learner,
      absl::FunctionRef<absl::StatusOr<CheckpointExtras>()> extras);

 private:
  double Seconds() const;
  absl::Status WriteRunCheckpoint(
      const LearnerCore& learner, double elapsed_seconds,
      absl::FunctionRef<absl::StatusOr<CheckpointExtras>()> extras);

  // Whether `version` is evaluated (and so checkpointed and held).
  bool Evaluates(int64_t version) const;
  // The best checkpoint keeps the evaluated versions that beat it.
  absl::Status OfferToBest(const std::vector<PolicyEvaluation>& evaluations);

  std::optional<RunDirectory> run_;
  RecorderConfig config_;
  int64_t eval_every_ = 0;
  std::optional<BestCheckpoint> best_;
  std::chrono::steady_clock::time_point start_;
  int64_t checkpointed_version_ = -1;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_RUN_RECORDER_H_
