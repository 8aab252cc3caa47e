#include "learner/run/training_run.h"

#include <cstdio>
#include <optional>
#include <string>
#include <utility>

#include "learner/run/batch_memory.h"
#include "learner/run/run_directory.h"
#include "learner/run/run_resume.h"

namespace vantage {

TrainingRun::TrainingRun(std::unique_ptr<LearnerCore> learner,
                         RunRecorder recorder, int64_t total_env_steps)
    : learner_(std::move(learner)),
      recorder_(std::move(recorder)),
      total_env_steps_(total_env_steps) {}

absl::StatusOr<std::unique_ptr<TrainingRun>> TrainingRun::Open(
    const RecordingConfig& recording, const LearnerConfig& learner_config,
    const RestoreExtras& restore, std::shared_ptr<ReplicaGroup> replicas) {
  KeepFreedMemoryForLargeBatches(learner_config);
  std::optional<RunDirectory> run;
  std::unique_ptr<LearnerCore> learner;
  double elapsed_before = 0.0;
  if (recording.resume) {
    absl::StatusOr<RunDirectory> opened = RunDirectory::Open(recording.run_dir);
    if (!opened.ok()) return opened.status();
    run = *std::move(opened);
    absl::StatusOr<ResumePoint> resumed = ResumeFromNewestCheckpoint(
        *run, /*truncate_progress=*/recording.record,
        [&](const std::string& path, const CheckpointExtras& extras)
            -> absl::StatusOr<std::unique_ptr<LearnerCore>> {
          absl::StatusOr<std::unique_ptr<LearnerCore>> loaded =
              ReadCheckpoint(path, learner_config, replicas);
          if (!loaded.ok() || !restore) return loaded;
          if (absl::Status status = restore(path, extras); !status.ok()) {
            return status;
          }
          return loaded;
        });
    if (!resumed.ok()) return resumed.status();
    learner = std::move(resumed->learner);
    elapsed_before = resumed->elapsed_seconds;
    if (!recording.record) run.reset();
  } else {
    if (!recording.run_dir.empty() && recording.record) {
      absl::StatusOr<RunDirectory> created =
          RunDirectory::Create(recording.run_dir, recording.config_json);
      if (!created.ok()) return created.status();
      run = *std::move(created);
    }
    absl::StatusOr<std::unique_ptr<LearnerCore>> created =
        LearnerCore::Create(learner_config, replicas);
    if (!created.ok()) return created.status();
    learner = *std::move(created);
  }
  if (run.has_value()) {
    if (absl::Status status = run->RecordMachine(); !status.ok()) {
      return status;
    }
  }
  RecorderConfig recorder;
  recorder.recording = recording;
  recorder.total_env_steps = learner_config.total_env_steps;
  recorder.elapsed_before = elapsed_before;
  recorder.steps_before = learner->env_steps();
  const int64_t total = learner_config.total_env_steps;
  return std::unique_ptr<TrainingRun>(new TrainingRun(
      std::move(learner), RunRecorder(std::move(run), recorder), total));
}

bool TrainingRun::done() const {
  return learner_->env_steps() >= total_env_steps_;
}

absl::StatusOr<ProgressRow> TrainingRun::Update(SegmentQueue& queue,
                                                const SaveExtras& save) {
  absl::StatusOr<UpdateStats> stats = learner_->RunUpdate(queue);
  if (!stats.ok()) return stats.status();
  // A segment that reached the learner and was refused there is a bug of
  // its sender (the gateway refuses bad ones at the door): say why.
  if (!stats->first_rejection.empty()) {
    std::fprintf(stderr, "learner: refused a segment (%ld so far): %s\n",
                 static_cast<long>(stats->rejected_segments),
                 stats->first_rejection.c_str());
  }
  return recorder_.Record(*learner_, *stats, Evaluations(), save);
}

absl::Status TrainingRun::EvaluateEvery(int64_t every, EvaluatePolicy evaluate,
                                        bool in_background) {
  if (absl::Status status = recorder_.EvaluateEvery(every); !status.ok()) {
    return status;
  }
  eval_every_ = every;
  evaluate_ = std::move(evaluate);
  if (in_background) {
    background_ = std::make_unique<BackgroundEvaluator>(evaluate_);
  }
  return absl::OkStatus();
}

std::vector<PolicyEvaluation> TrainingRun::Evaluations() {
  std::vector<PolicyEvaluation> evaluations;
  const int64_t version = learner_->policy_version();
  if (eval_every_ > 0 && version % eval_every_ == 0) {
    if (background_ != nullptr) {
      background_->Submit(learner_->CurrentWeights());
    } else if (absl::StatusOr<PolicyEvaluation> evaluation =
                   evaluate_(learner_->CurrentWeights());
               evaluation.ok()) {
      evaluations.push_back(*std::move(evaluation));
    } else {
      // Training goes on: an evaluation is a measurement, not the run.
      std::fprintf(stderr,
                   "learner: the evaluation of version %ld failed: %s\n",
                   static_cast<long>(version),
                   std::string(evaluation.status().message()).c_str());
    }
  }
  if (background_ == nullptr) return evaluations;
  // The run's last row waits for its final evaluations.
  if (done()) background_->Drain();
  return background_->TakeFinished();
}

absl::Status TrainingRun::CheckpointNow(const SaveExtras& save) {
  return recorder_.CheckpointNow(*learner_, save);
}

}  // namespace vantage
