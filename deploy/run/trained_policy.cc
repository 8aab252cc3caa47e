#include "deploy/run/trained_policy.h"

#include <filesystem>
#include <utility>

#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"
#include "common/nn/policy_runner.h"
#include "deploy/export/policy_onnx.h"
#include "deploy/run/run_config.h"
#include "deploy/run/run_plan.h"
#include "learner/checkpoint/checkpoint.h"

namespace vantage {

struct TrainedPolicy::Networks {
  explicit Networks(PolicyRunner runner) : runner(std::move(runner)) {}
  PolicyRunner runner;
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
  PolicyRunner runner((*env)->spec(), learner_config.network,
                      learner_config.observation_clip);
  if (absl::Status status = runner.Load((*learner)->CurrentWeights());
      !status.ok()) {
    return status;
  }
  trained.networks =
      std::make_shared<TrainedPolicy::Networks>(std::move(runner));
  return trained;
}

}  // namespace

void TrainedPolicy::Seed(uint64_t seed) { networks->runner.Seed(seed); }

void TrainedPolicy::StartEpisode() { networks->runner.StartEpisode(); }

std::vector<double> TrainedPolicy::Act(absl::Span<const double> observation,
                                       bool deterministic,
                                       absl::Span<const uint8_t> mask) {
  return networks->runner.Act(observation, deterministic, mask);
}

absl::StatusOr<std::string> TrainedPolicy::OnnxModel(bool distribution) const {
  OnnxExportOptions options;
  options.distribution = distribution;
  options.producer_version = absl::StrCat("policy version ", version);
  const PolicyRunner& runner = networks->runner;
  return PolicyToOnnx(spec, runner.policy(), runner.normalizer(),
                      runner.observation_clip(), options);
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
