#include "deploy/run/trained_policy.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <ATen/core/grad_mode.h>

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "deploy/export/policy_onnx.h"
#include "deploy/run/run_config.h"
#include "deploy/run/run_plan.h"
#include "learner/checkpoint/checkpoint.h"

namespace vantage {

struct TrainedPolicy::Networks {
  PolicyNetwork policy{nullptr};
  RunningMeanStd normalizer{1};
  double observation_clip = 10.0;
  at::Generator generator = at::detail::createCPUGenerator(0);
  at::Tensor state;  // a recurrent policy's, [1, state size]
};

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
  absl::StatusOr<RunPlan> plan = PlanRun(*config);
  if (!plan.ok()) return plan.status();
  LearnerConfig learner_config = plan->learner;
  learner_config.spec = (*env)->spec();
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      ReadCheckpoint(path, learner_config);
  if (!learner.ok()) return learner.status();
  TrainedPolicy trained;
  trained.config = *config;
  trained.checkpoint_path = path;
  trained.version = (*learner)->policy_version();
  trained.spec = (*env)->spec();
  trained.networks = std::make_shared<TrainedPolicy::Networks>();
  TrainedPolicy::Networks& networks = *trained.networks;
  networks.policy = PolicyNetwork((*env)->spec(), learner_config.network);
  networks.normalizer = RunningMeanStd((*env)->spec().observation_size);
  networks.observation_clip = learner_config.observation_clip;
  if (absl::Status status = ImportPolicyWeights(
          (*learner)->CurrentWeights(), *networks.policy, networks.normalizer);
      !status.ok()) {
    return status;
  }
  trained.StartEpisode();
  return trained;
}

}  // namespace

void TrainedPolicy::Seed(uint64_t seed) {
  networks->generator = at::detail::createCPUGenerator(seed);
}

void TrainedPolicy::StartEpisode() {
  Networks& n = *networks;
  if (n.policy->recurrent()) n.state = n.policy->trunk()->InitialState(1);
}

std::vector<double> TrainedPolicy::Act(absl::Span<const double> observation,
                                       bool deterministic) {
  at::NoGradGuard no_grad;
  Networks& n = *networks;
  const at::Tensor x = ObservationsForNetwork(
      spec, n.normalizer, ObservationTensor(spec, observation.data(), 1),
      n.observation_clip);
  const at::Tensor output =
      n.policy->recurrent() ? n.policy->Step(x, n.state) : n.policy->forward(x);
  const at::Tensor action = n.policy->Act(output, deterministic, n.generator)
                                .to(at::kDouble)
                                .contiguous();
  const double* data = action.data_ptr<double>();
  return std::vector<double>(data, data + action.numel());
}

absl::StatusOr<std::string> TrainedPolicy::OnnxModel(bool distribution) const {
  OnnxExportOptions options;
  options.distribution = distribution;
  options.producer_version = absl::StrCat("policy version ", version);
  return PolicyToOnnx(spec, *networks->policy, networks->normalizer,
                      networks->observation_clip, options);
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
