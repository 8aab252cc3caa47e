#include "learner/algorithms/a2c/a2c_updater.h"

#include <ATen/ATen.h>
#include <torch/optim/rmsprop.h>

#include <algorithm>
#include <cmath>
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
                       std::shared_ptr<ReplicaGroup> replicas,
                       bool autograd_only)
    : policy_(std::move(policy)),
      value_(std::move(value)),
      config_(config),
      replicas_(std::move(replicas)),
      parameters_(NetworkParameters(*policy_, *value_)),
      optimizer_(MakeRmsprop(parameters_, config)),
      flat_(MakeFlatActorCritic(*policy_, *value_, parameters_, "A2C",
                                autograd_only)) {
  if (flat_.has_value()) {
    flat_rmsprop_.emplace(parameters_, flat_->offsets(), flat_->size(),
                          config.rmsprop == "pytorch"
                              ? RmspropArithmetic::kPytorch
                              : RmspropArithmetic::kTensorflow);
  }
}

A2cUpdater::~A2cUpdater() = default;

AlgorithmStats A2cUpdater::Update(const UpdateBatch& batch, double progress,
                                  std::mt19937_64& /*rng*/) {
  SetLearningRate(*optimizer_,
                  config_.learning_rate * std::max(0.0, 1.0 - progress));
  const int64_t rows = config_.steps_per_minibatch * batch.streams;
  return flat_.has_value() ? FlatUpdate(batch, rows)
                           : AutogradUpdate(batch, rows);
}

AlgorithmStats A2cUpdater::FlatUpdate(const UpdateBatch& batch, int64_t rows) {
  FlatActorCritic& net = *flat_;
  // The modules may have been rolled back or loaded since the last update.
  net.Pull();
  const int64_t size = batch.observations.size(0);
  const at::Tensor inputs = net.Inputs(batch.observations);
  const at::Tensor actions = FloatRows(batch.actions, size);
  const at::Tensor behaviour = FloatRows(batch.behaviour_log_probs, size);
  const at::Tensor advantages = FloatRows(batch.advantages, size);
  const at::Tensor returns = FloatRows(batch.returns, size);
  d_log_probs_.resize(rows);
  d_values_.resize(rows);
  const double count = static_cast<double>(rows);
  MeanStats stats;
  // The minibatches are consecutive rows: no gathering.
  for (int64_t begin = 0; begin + rows <= size; begin += rows) {
    const float* adv = advantages.data_ptr<float>() + begin;
    const float* old_log_prob = behaviour.data_ptr<float>() + begin;
    const float* target = returns.data_ptr<float>() + begin;
    net.Forward(inputs.data_ptr<float>() + begin * inputs.size(1),
                actions.data_ptr<float>() + begin * actions.size(1), rows);
    const float* log_probs = net.log_probs();
    const float* values = net.values();
    double policy_loss = 0.0, value_loss = 0.0, approx_kl = 0.0;
    for (int64_t i = 0; i < rows; ++i) {
      policy_loss -= static_cast<double>(log_probs[i]) * adv[i];
      d_log_probs_[i] = static_cast<float>(-adv[i] / count);
      const float error = values[i] - target[i];
      value_loss += 0.5 * error * error;
      d_values_[i] = static_cast<float>(config_.value_coef * error / count);
      const float log_ratio = log_probs[i] - old_log_prob[i];
      approx_kl += (std::exp(log_ratio) - 1.0f) - log_ratio;
    }
    net.Backward(d_log_probs_.data(), -config_.entropy_coef, d_values_.data());
    AlgorithmStats step;
    step.max_gradient_norm = AverageAndClipFlatGradient(
        net.gradients(), net.size(), config_.max_grad_norm, *replicas_);
    flat_rmsprop_->Step(*optimizer_, net.parameters(), net.gradients());
    step.policy_loss = policy_loss / count;
    step.value_loss = value_loss / count;
    step.entropy = net.mean_entropy();
    step.approx_kl = approx_kl / count;
    step.clip_fraction = std::numeric_limits<double>::quiet_NaN();
    stats.Add(step);
  }
  net.Push();
  return stats.Mean();
}

AlgorithmStats A2cUpdater::AutogradUpdate(const UpdateBatch& batch,
                                          int64_t rows) {
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
  if (flat_rmsprop_.has_value()) flat_rmsprop_->StoreInto(*optimizer_);
  SaveOptimizer(*optimizer_, OptimizerKey(config_), archive);
}

absl::Status A2cUpdater::Load(torch::serialize::InputArchive& archive) {
  if (absl::Status status =
          LoadOptimizer(*optimizer_, OptimizerKey(config_), archive);
      !status.ok() || !flat_rmsprop_.has_value()) {
    return status;
  }
  return flat_rmsprop_->LoadFrom(*optimizer_);
}

}  // namespace vantage
