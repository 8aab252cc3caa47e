#include "actor/policy_evaluator.h"

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"
#include "common/nn/distributions.h"
#include "common/nn/mlp_policy_kernel.h"
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

// The deterministic action through MlpPolicyKernel (BLAS, no per-operator
// dispatch: an evaluation beside a learner should cost it little), or
// through LibTorch for a policy the kernel cannot run.
struct PolicyEvaluator::FastPolicy {
  MlpPolicyKernel kernel;
  std::vector<float> outputs;
  std::vector<float> state;

  void StartEpisode() { std::fill(state.begin(), state.end(), 0.0f); }
  std::vector<double> Act(const EnvSpec& spec,
                          const std::vector<double>& observation,
                          const std::vector<uint8_t>& mask) {
    kernel.Forward(observation.data(), 1, outputs.data(),
                   state.empty() ? nullptr : state.data());
    if (!spec.discrete) return {outputs.begin(), outputs.end()};
    if (!mask.empty()) {
      MaskLogitsInPlace(outputs.data(), mask.data(), 1, spec.action_size);
    }
    // The most likely choice of each head.
    std::vector<double> action;
    auto head = outputs.begin();
    for (int64_t choices : kernel.heads()) {
      action.push_back(
          static_cast<double>(std::max_element(head, head + choices) - head));
      head += choices;
    }
    return action;
  }
};

PolicyEvaluator::~PolicyEvaluator() = default;

const EnvSpec& PolicyEvaluator::spec() const { return env_->spec(); }

absl::StatusOr<PolicyEvaluation> PolicyEvaluator::Evaluate(
    const PolicyWeights& weights) {
  if (absl::Status status = runner_->Load(weights); !status.ok()) {
    return status;
  }
  fast_.reset();
  absl::StatusOr<MlpPolicyKernel> kernel =
      MlpPolicyKernel::Create(spec(), runner_->policy(), runner_->normalizer(),
                              runner_->observation_clip());
  if (kernel.ok()) {
    fast_ =
        std::make_unique<FastPolicy>(FastPolicy{*std::move(kernel), {}, {}});
    fast_->outputs.resize(fast_->kernel.output_size());
    fast_->state.resize(fast_->kernel.state_size());
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
  if (fast_ != nullptr) fast_->StartEpisode();
  while (length < kMaxEpisodeSteps) {
    absl::StatusOr<std::vector<uint8_t>> mask = ReadActionMask(*env_);
    if (!mask.ok()) return mask.status();
    const std::vector<double> action =
        fast_ != nullptr
            ? fast_->Act(env_->spec(), observation, *mask)
            : runner_->Act(observation, /*deterministic=*/true, *mask);
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
