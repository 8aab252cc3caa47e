#ifndef VANTAGE_LEARNER_RUN_TRAINING_RUN_H_
#define VANTAGE_LEARNER_RUN_TRAINING_RUN_H_

// The life of one training run that local and distributed training share:
// its run directory created (or opened to resume), its learner created (or
// loaded from the newest checkpoint that loads), and every update recorded
// (a progress row, checkpoints). Only where segments come from differs: an
// in-process actor (deploy/run/local_training.h) or the gRPC service
// (learner/server/learner_server.h) fills the queue each update consumes.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/rollout/segment_queue.h"
#include "learner/checkpoint/checkpoint.h"
#include "learner/learner_core.h"
#include "learner/run/background_evaluator.h"
#include "learner/run/progress_columns.h"
#include "learner/run/recording_config.h"
#include "learner/run/run_recorder.h"

namespace vantage {

class TrainingRun {
 public:
  // What the caller keeps in a checkpoint besides the learner (the local
  // actor's state, the server's spec and next actor id); called only when
  // one is written.
  using SaveExtras = std::function<absl::StatusOr<CheckpointExtras>()>;
  // Restores the caller's own state from a checkpoint whose learner loaded;
  // an error makes a resume try the checkpoint before it.
  using RestoreExtras = std::function<absl::Status(
      const std::string& path, const CheckpointExtras& extras)>;

  // A new run (its directory, if `recording.run_dir` is set, must not hold
  // one) or, with `recording.resume`, the run in `recording.run_dir`
  // continued from its newest checkpoint that loads with `learner` and
  // `restore`. The learner is one of `replicas`; its total_env_steps end
  // the run.
  static absl::StatusOr<std::unique_ptr<TrainingRun>> Open(
      const RecordingConfig& recording, const LearnerConfig& learner,
      const RestoreExtras& restore,
      std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());

  LearnerCore& learner() { return *learner_; }

  // Evaluates every `every` updates' version with `evaluate`: in the
  // background (a learner process: its results go into the first row after
  // they finish), or before the update's row, which holds it (a local run,
  // so that a rerun or a resume repeats it). Keeps checkpoints/best.pt.
  absl::Status EvaluateEvery(int64_t every, EvaluatePolicy evaluate,
                             bool in_background);
  // The run's environment steps are done.
  bool done() const;

  // One update from `queue` (blocking until it holds a batch), recorded.
  absl::StatusOr<ProgressRow> Update(SegmentQueue& queue,
                                     const SaveExtras& save);
  // A checkpoint now unless the current version has one (see
  // RunRecorder::CheckpointNow): a run stopped by a signal loses nothing.
  absl::Status CheckpointNow(const SaveExtras& save);

 private:
  TrainingRun(std::unique_ptr<LearnerCore> learner, RunRecorder recorder,
              int64_t total_env_steps);

  // The evaluations to record with this update's row.
  std::vector<PolicyEvaluation> Evaluations();

  std::unique_ptr<LearnerCore> learner_;
  RunRecorder recorder_;
  const int64_t total_env_steps_;
  int64_t eval_every_ = 0;
  EvaluatePolicy evaluate_;
  std::unique_ptr<BackgroundEvaluator> background_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_TRAINING_RUN_H_
