#include "deploy/trained_policy.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"
#include "common/nn/policy_weights.h"
#include "deploy/local_training.h"
#include "deploy/run_config.h"
#include "learner/checkpoint.h"

namespace vantage {
namespace {

absl::StatusOr<TrainedPolicy> LoadCheckpointFile(const std::string& path) {
  absl::StatusOr<CheckpointExtras> extras = ReadCheckpointExtras(path);
  if (!extras.ok()) return extras.status();
  if (extras->count("config") == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, " holds no run config"));
  }
  absl::StatusOr<pb::RunConfig> parsed =
      ParseRunConfigJson(extras->at("config"));
  if (!parsed.ok()) return parsed.status();
  absl::StatusOr<pb::RunConfig> config = ResolveRunConfig(*parsed);
  if (!config.ok()) return config.status();
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(config->training().env(), EnvOptionsOf(*config));
  if (!env.ok()) return env.status();
  const LocalTrainingConfig local = ToLocalTrainingConfig(*config);
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      ReadCheckpoint(path, MakeLearnerConfig(local, (*env)->spec()));
  if (!learner.ok()) return learner.status();
  TrainedPolicy trained;
  trained.config = *config;
  trained.checkpoint_path = path;
  trained.version = (*learner)->policy_version();
  trained.spec = (*env)->spec();
  trained.policy = PolicyNetwork((*env)->spec(), local.learner.network);
  trained.normalizer = RunningMeanStd((*env)->spec().observation_size);
  trained.observation_clip = local.learner.observation_clip;
  if (absl::Status status = ImportPolicyWeights(
          (*learner)->CurrentWeights(), *trained.policy, trained.normalizer);
      !status.ok()) {
    return status;
  }
  return trained;
}

}  // namespace

std::vector<double> TrainedPolicy::Act(absl::Span<const double> observation,
                                       bool deterministic,
                                       at::Generator generator) {
  at::NoGradGuard no_grad;
  const at::Tensor x = ObservationTensor(spec, observation.data(), 1);
  const at::Tensor action =
      policy
          ->Act(policy->forward(ObservationsForNetwork(spec, normalizer, x,
                                                       observation_clip)),
                deterministic, generator)
          .to(at::kDouble)
          .contiguous();
  const double* data = action.data_ptr<double>();
  return std::vector<double>(data, data + action.numel());
}

absl::StatusOr<TrainedPolicy> LoadTrainedPolicy(const std::string& path) {
  if (!std::filesystem::is_directory(path)) return LoadCheckpointFile(path);
  const std::vector<std::string> paths = ListCheckpoints(path + "/checkpoints");
  if (paths.empty()) {
    return absl::NotFoundError(
        absl::StrCat(path, " holds no checkpoints/checkpoint-*.pt"));
  }
  absl::Status last;
  for (auto file = paths.rbegin(); file != paths.rend(); ++file) {
    absl::StatusOr<TrainedPolicy> trained = LoadCheckpointFile(*file);
    if (trained.ok()) return trained;
    last = trained.status();
  }
  return last;
}

}  // namespace vantage
