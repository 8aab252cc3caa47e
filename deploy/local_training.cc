#include "deploy/local_training.h"

#include <chrono>
#include <cstdio>
#include <optional>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "deploy/run_directory.h"
#include "deploy/run_recorder.h"
#include "learner/checkpoint.h"

namespace vantage {
namespace {

constexpr char kActorState[] = "actor_state";

struct Resumed {
  std::unique_ptr<LearnerCore> learner;
  double elapsed_seconds = 0.0;
};

// The newest checkpoint that loads, with the actor restored to the state it
// had then. Unreadable newer ones are reported on stderr and skipped.
absl::StatusOr<Resumed> ResumeFromCheckpoint(const RunDirectory& run,
                                             const LearnerConfig& config,
                                             ActorCore& actor) {
  const std::vector<std::string> paths =
      ListCheckpoints(run.checkpoint_directory());
  if (paths.empty()) {
    return absl::NotFoundError(
        absl::StrCat(run.path(), " has no checkpoint to resume from"));
  }
  std::string problems;
  for (auto path = paths.rbegin(); path != paths.rend(); ++path) {
    absl::StatusOr<CheckpointExtras> extras = ReadCheckpointExtras(*path);
    absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
        extras.ok()
            ? ReadCheckpoint(*path, config)
            : absl::StatusOr<std::unique_ptr<LearnerCore>>(extras.status());
    absl::Status status = learner.status();
    if (status.ok() && extras->count(kActorState) == 0) {
      status = absl::InvalidArgumentError(
          absl::StrCat(*path, " holds no actor state"));
    }
    if (status.ok()) status = actor.RestoreState(extras->at(kActorState));
    if (status.ok()) {
      Resumed resumed;
      resumed.learner = *std::move(learner);
      if (extras->count(kCheckpointElapsed) != 0) {
        (void)absl::SimpleAtod(extras->at(kCheckpointElapsed),
                               &resumed.elapsed_seconds);
      }
      return resumed;
    }
    std::fprintf(stderr, "vantage: skipping checkpoint %s: %s\n", path->c_str(),
                 std::string(status.message()).c_str());
    absl::StrAppend(&problems, problems.empty() ? "" : "; ", status.message());
  }
  return absl::DataLossError(absl::StrCat(
      "no checkpoint in ", run.checkpoint_directory(), " loads: ", problems));
}

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
    absl::StatusOr<Resumed> resumed =
        ResumeFromCheckpoint(*run, learner_config, **actor);
    if (!resumed.ok()) return resumed.status();
    learner = std::move(resumed->learner);
    elapsed_before = resumed->elapsed_seconds;
    if (absl::Status status = run->TruncateProgress(learner->policy_version());
        !status.ok()) {
      return status;
    }
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
