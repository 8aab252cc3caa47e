#include "deploy/local_training.h"

#include <chrono>
#include <cstdio>
#include <optional>

#include "absl/strings/str_cat.h"
#include "deploy/run_directory.h"
#include "deploy/run_recorder.h"
#include "deploy/run_resume.h"
#include "learner/checkpoint.h"

namespace vantage {
namespace {

constexpr char kActorState[] = "actor_state";

}  // namespace

LearnerConfig MakeLearnerConfig(const LocalTrainingConfig& config,
                                const EnvSpec& spec) {
  LearnerConfig learner = config.learner;
  learner.spec = spec;
  learner.rollouts_per_batch = config.num_envs;
  learner.max_segment_steps = config.learner.horizon;
  learner.total_env_steps = config.total_env_steps;
  learner.seed = config.seed;
  return learner;
}

absl::Status RunLocalTraining(
    const LocalTrainingConfig& config,
    const std::function<bool(const ProgressRow&)>& on_update) {
  ActorConfig actor_config;
  actor_config.env = config.env;
  actor_config.num_envs = config.num_envs;
  const int64_t segment_length = config.segment_length > 0
                                     ? config.segment_length
                                     : config.learner.horizon;
  if (config.learner.horizon % segment_length != 0) {
    return absl::InvalidArgumentError(
        "the segment length must divide the horizon");
  }
  const int64_t rounds = config.learner.horizon / segment_length;
  actor_config.segment_length = segment_length;
  actor_config.seed = config.seed;
  actor_config.network = config.learner.network;
  actor_config.observation_clip = config.learner.observation_clip;
  absl::StatusOr<std::unique_ptr<ActorCore>> actor =
      ActorCore::Create(actor_config);
  if (!actor.ok()) return actor.status();

  const LearnerConfig learner_config =
      MakeLearnerConfig(config, (*actor)->spec());

  std::optional<RunDirectory> run;
  std::unique_ptr<LearnerCore> learner;
  double elapsed_before = 0.0;
  if (config.resume) {
    absl::StatusOr<RunDirectory> opened = RunDirectory::Open(config.run_dir);
    if (!opened.ok()) return opened.status();
    run = *std::move(opened);
    // The actor continues exactly where the checkpoint's actor was.
    absl::StatusOr<ResumePoint> resumed = ResumeFromNewestCheckpoint(
        *run,
        [&](const std::string& path, const CheckpointExtras& extras)
            -> absl::StatusOr<std::unique_ptr<LearnerCore>> {
          auto state = extras.find(kActorState);
          if (state == extras.end()) {
            return absl::InvalidArgumentError(
                absl::StrCat(path, " holds no actor state"));
          }
          absl::StatusOr<std::unique_ptr<LearnerCore>> loaded =
              ReadCheckpoint(path, learner_config);
          if (!loaded.ok()) return loaded.status();
          if (absl::Status status = (*actor)->RestoreState(state->second);
              !status.ok()) {
            return status;
          }
          return loaded;
        });
    if (!resumed.ok()) return resumed.status();
    learner = std::move(resumed->learner);
    elapsed_before = resumed->elapsed_seconds;
  } else {
    if (!config.run_dir.empty()) {
      absl::StatusOr<RunDirectory> created =
          RunDirectory::Create(config.run_dir, config.config_json);
      if (!created.ok()) return created.status();
      run = *std::move(created);
    }
    absl::StatusOr<std::unique_ptr<LearnerCore>> created =
        LearnerCore::Create(learner_config);
    if (!created.ok()) return created.status();
    learner = *std::move(created);
  }

  RecorderConfig recorder_config;
  recorder_config.config_json = config.config_json;
  recorder_config.checkpoint_every = config.checkpoint_every;
  recorder_config.keep_checkpoints = config.keep_checkpoints;
  recorder_config.total_env_steps = config.total_env_steps;
  recorder_config.elapsed_before = elapsed_before;
  recorder_config.steps_before = learner->env_steps();
  RunRecorder recorder(std::move(run), recorder_config);
  auto actor_state = [&]() -> absl::StatusOr<CheckpointExtras> {
    absl::StatusOr<std::string> state = (*actor)->SaveState();
    if (!state.ok()) return state.status();
    return CheckpointExtras{{kActorState, *std::move(state)}};
  };

  // One horizon of segments per version, all queued before the update.
  SegmentQueue queue(static_cast<size_t>(config.num_envs * rounds));
  while (learner->env_steps() < config.total_env_steps) {
    if (absl::Status status = (*actor)->SetWeights(learner->CurrentWeights());
        !status.ok()) {
      return status;
    }
    for (int64_t round = 0; round < rounds; ++round) {
      if (absl::Status status = (*actor)->CollectSegments(queue);
          !status.ok()) {
        return status;
      }
    }
    absl::StatusOr<UpdateStats> stats = learner->RunUpdate(queue);
    if (!stats.ok()) return stats.status();
    absl::StatusOr<ProgressRow> progress =
        recorder.Record(*learner, *stats, actor_state);
    if (!progress.ok()) return progress.status();
    if (!on_update(*progress)) break;
  }
  return absl::OkStatus();
}

}  // namespace vantage
