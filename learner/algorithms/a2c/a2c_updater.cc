#include "learner/algorithms/a2c/a2c_updater.h"

#include <ATen/ATen.h>
#include <torch/optim/rmsprop.h>

#include <algorithm>
#include <limits>

#include "learner/algorithms/a2c/tensorflow_rmsprop.h"
#include "learner/algorithms/gradient_step.h"

namespace vantage {
namespace {

std::unique_ptr<torch::optim::Optimizer> MakeRmsprop(
    const std::vector<at::Tensor>& parameters, const A2cConfig& config) {
  const auto options = torch::optim::RMSpropOptions(config.learning_rate)
                           .alpha(config.rmsprop_alpha)
                           .eps(config.rmsprop_eps);
  if (config.rmsprop == "pytorch") {
    return std::make_unique<torch::optim::RMSprop>(parameters, options);
  }
  return std::make_unique<TensorflowRmsprop>(parameters, options);
}

// The two arithmetics keep the same state, so the checkpoint key says which
// one made it: a run cannot silently continue under the other.
std::string OptimizerKey(const A2cConfig& config) {
  return config.rmsprop == "pytorch" ? "rmsprop" : "rmsprop_tensorflow";
}

}  // namespace

A2cUpdater::A2cUpdater(PolicyNetwork policy, ValueNetwork value,
                       const A2cConfig& config,
                       std::shared_ptr<ReplicaGroup> replicas)
    : policy_(std::move(policy)),
      value_(std::move(value)),
      config_(config),
      replicas_(std::move(replicas)),
      parameters_(NetworkParameters(*policy_, *value_)),
      optimizer_(MakeRmsprop(parameters_, config)) {}

A2cUpdater::~A2cUpdater() = default;

AlgorithmStats A2cUpdater::Update(const UpdateBatch& batch, double progress,
                                  std::mt19937_64& /*rng*/) {
  SetLearningRate(*optimizer_,
                  config_.learning_rate * std::max(0.0, 1.0 - progress));
  const int64_t rows = config_.steps_per_minibatch * batch.streams;
  const int64_t size = batch.observations.size(0);
  MeanStats stats;
  for (int64_t begin = 0; begin + rows <= size; begin += rows) {
    const at::Tensor obs = batch.observations.slice(0, begin, begin + rows);
    const at::Tensor adv = batch.advantages.slice(0, begin, begin + rows);
    const at::Tensor old_log_prob =
        batch.behaviour_log_probs.slice(0, begin, begin + rows);
    const at::Tensor output = policy_->forward(obs);
    const at::Tensor log_prob =
        policy_->LogProb(output, batch.actions.slice(0, begin, begin + rows));
    const at::Tensor policy_loss = -(log_prob * adv).mean();
    const at::Tensor entropy = policy_->Entropy(output).mean();
    const at::Tensor value_loss =
        ValueLoss(*value_, obs, batch.returns.slice(0, begin, begin + rows));
    const double gradient_norm =
        GradientStep(*optimizer_, parameters_,
                     policy_loss + config_.value_coef * value_loss -
                         config_.entropy_coef * entropy,
                     config_.max_grad_norm, *replicas_);
    AlgorithmStats step;
    step.max_gradient_norm = gradient_norm;
    step.policy_loss = policy_loss.item<double>();
    step.value_loss = value_loss.item<double>();
    step.entropy = entropy.item<double>();
    // Later minibatches act on an already-updated policy; this is how far
    // it has moved from the behaviour policy (the same estimator as PPO's).
    const at::Tensor log_ratio = log_prob.detach() - old_log_prob;
    step.approx_kl =
        ((at::exp(log_ratio) - 1) - log_ratio).mean().item<double>();
    step.clip_fraction = std::numeric_limits<double>::quiet_NaN();
    stats.Add(step);
  }
  return stats.Mean();
}

void A2cUpdater::Save(torch::serialize::OutputArchive& archive) const {
  SaveOptimizer(*optimizer_, OptimizerKey(config_), archive);
}

absl::Status A2cUpdater::Load(torch::serialize::InputArchive& archive) {
  return LoadOptimizer(*optimizer_, OptimizerKey(config_), archive);
}

}  // namespace vantage
