#include "actor/policy_evaluator.h"

#include <random>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"
#include "common/nn/policy_runner.h"

namespace vantage {
namespace {

// Salts the run's seed so that evaluation episodes share no reset seed
// with training's environments, whose generators take the actor's seed.
constexpr uint64_t kEvaluationSeedSalt = 0x6576616c75617465ULL;  // "evaluate"

}  // namespace

absl::StatusOr<std::unique_ptr<PolicyEvaluator>> PolicyEvaluator::Create(
    const ActorConfig& actor, int episodes) {
  if (episodes < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("an evaluation needs >= 1 episode, got ", episodes));
  }
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(actor.env, actor.env_options);
  if (!env.ok()) return env.status();
  auto runner = std::make_unique<PolicyRunner>((*env)->spec(), actor.network,
                                               actor.observation_clip);
  return std::unique_ptr<PolicyEvaluator>(
      new PolicyEvaluator(*std::move(env), std::move(runner), episodes,
                          actor.seed ^ kEvaluationSeedSalt));
}

PolicyEvaluator::PolicyEvaluator(std::unique_ptr<Environment> env,
                                 std::unique_ptr<PolicyRunner> runner,
                                 int episodes, uint64_t seed)
    : env_(std::move(env)),
      runner_(std::move(runner)),
      episodes_(episodes),
      seed_(seed) {}

PolicyEvaluator::~PolicyEvaluator() = default;

const EnvSpec& PolicyEvaluator::spec() const { return env_->spec(); }

absl::StatusOr<PolicyEvaluation> PolicyEvaluator::Evaluate(
    const PolicyWeights& weights) {
  if (absl::Status status = runner_->Load(weights); !status.ok()) {
    return status;
  }
  PolicyEvaluation evaluation;
  evaluation.version = weights.version;
  std::mt19937_64 seeds(seed_);
  for (int episode = 0; episode < episodes_; ++episode) {
    double total = 0.0;
    int64_t length = 0;
    if (absl::Status status = PlayEpisode(seeds(), total, length);
        !status.ok()) {
      return status;
    }
    evaluation.returns.push_back(total);
    evaluation.lengths.push_back(length);
  }
  return evaluation;
}

absl::Status PolicyEvaluator::PlayEpisode(uint64_t seed, double& total,
                                          int64_t& length) {
  std::vector<double> observation(env_->spec().observation_size);
  if (absl::Status status = env_->Reset(seed, absl::MakeSpan(observation));
      !status.ok()) {
    return status;
  }
  runner_->StartEpisode();
  while (length < kMaxEpisodeSteps) {
    const std::vector<double> action =
        runner_->Act(observation, /*deterministic=*/true);
    absl::StatusOr<StepResult> step =
        env_->Step(action, absl::MakeSpan(observation));
    if (!step.ok()) return step.status();
    total += step->reward;
    ++length;
    if (step->terminated || step->truncated) break;
  }
  return absl::OkStatus();
}

}  // namespace vantage
