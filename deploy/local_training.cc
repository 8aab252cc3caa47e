#include "deploy/local_training.h"

#include <chrono>
#include <cstdio>
#include <optional>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "deploy/run_directory.h"
#include "learner/checkpoint.h"

namespace vantage {
namespace {

constexpr char kActorState[] = "actor_state";
constexpr char kConfig[] = "config";
constexpr char kElapsed[] = "elapsed_seconds";

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
      if (extras->count(kElapsed) != 0) {
        (void)absl::SimpleAtod(extras->at(kElapsed), &resumed.elapsed_seconds);
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
  const auto start = std::chrono::steady_clock::now();
  ActorConfig actor_config;
  actor_config.env = config.env;
  actor_config.num_envs = config.num_envs;
  actor_config.segment_length = config.learner.horizon;
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

  auto seconds_since_start = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  auto checkpoint = [&]() -> absl::Status {
    absl::StatusOr<std::string> actor_state = (*actor)->SaveState();
    if (!actor_state.ok()) return actor_state.status();
    const CheckpointExtras extras = {
        {kActorState, *actor_state},
        {kConfig, config.config_json},
        {kElapsed, absl::StrCat(elapsed_before + seconds_since_start())}};
    if (absl::Status status =
            WriteCheckpoint(CheckpointPath(run->checkpoint_directory(),
                                           learner->policy_version()),
                            *learner, extras);
        !status.ok()) {
      return status;
    }
    return PruneCheckpoints(run->checkpoint_directory(),
                            config.keep_checkpoints);
  };

  SegmentQueue queue(static_cast<size_t>(config.num_envs));
  const int64_t steps_before = learner->env_steps();
  while (learner->env_steps() < config.total_env_steps) {
    if (absl::Status status = (*actor)->SetWeights(learner->CurrentWeights());
        !status.ok()) {
      return status;
    }
    if (absl::Status status = (*actor)->CollectSegments(queue); !status.ok()) {
      return status;
    }
    absl::StatusOr<UpdateStats> stats = learner->RunUpdate(queue);
    if (!stats.ok()) return stats.status();
    ProgressRow progress;
    progress.stats = *stats;
    progress.mean_return = learner->MeanRecentReturn();
    const double seconds = seconds_since_start();
    progress.elapsed_seconds = elapsed_before + seconds;
    progress.steps_per_second =
        (stats->env_steps - steps_before) / std::max(seconds, 1e-9);
    if (run.has_value()) {
      if (absl::Status status = run->AppendProgress(progress); !status.ok()) {
        return status;
      }
      const bool last = stats->env_steps >= config.total_env_steps;
      if (last || stats->policy_version % config.checkpoint_every == 0) {
        if (absl::Status status = checkpoint(); !status.ok()) return status;
      }
    }
    if (!on_update(progress)) break;
  }
  return absl::OkStatus();
}

}  // namespace vantage
