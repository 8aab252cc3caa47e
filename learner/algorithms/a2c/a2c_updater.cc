#include "learner/algorithms/a2c/a2c_updater.h"

#include <ATen/ATen.h>
#include <torch/optim/rmsprop.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "learner/algorithms/a2c/flat_rmsprop.h"
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
    : FirstOrderUpdater(
          std::move(policy), std::move(value), std::move(replicas),
          GradientSettings{config.learning_rate, config.value_coef,
                           config.entropy_coef, config.max_grad_norm},
          "A2C", OptimizerKey(config), autograd_only),
      config_(config) {
  UseOptimizers(
      MakeRmsprop(parameters(), config),
      flat()
          ? std::make_unique<FlatRmsprop>(
                parameters(), flat_networks().offsets(), flat_networks().size(),
                config.rmsprop == "pytorch" ? RmspropArithmetic::kPytorch
                                            : RmspropArithmetic::kTensorflow)
          : nullptr);
}

A2cUpdater::~A2cUpdater() = default;

AlgorithmStats A2cUpdater::FlatUpdate(const UpdateBatch& batch,
                                      std::mt19937_64& /*rng*/) {
  const FlatRows flat_rows = StartFlatUpdate(batch);
  FlatActorCritic& net = flat_networks();
  const int64_t size = batch.observations.size(0);
  const int64_t rows = MinibatchRows(batch);
  const double count = static_cast<double>(rows);
  MeanStats stats;
  // The minibatches are consecutive rows: no gathering, but for a
  // recurrent policy, whose time slice is gathered chunk by chunk.
  for (int64_t begin = 0; begin + rows <= size; begin += rows) {
    const float* adv = flat_rows.advantages.data_ptr<float>() + begin;
    const float* old_log_prob = flat_rows.behaviour.data_ptr<float>() + begin;
    const float* target = flat_rows.returns.data_ptr<float>() + begin;
    if (net.recurrent()) {
      const Gathered gathered = GatherAndForward(
          flat_rows, ChunksOfSteps(batch, begin / batch.streams,
                                   config_.steps_per_minibatch));
      adv = gathered.advantages;
      old_log_prob = gathered.behaviour;
      target = gathered.returns;
    } else {
      net.Forward(
          flat_rows.inputs.data_ptr<float>() + begin * flat_rows.inputs.size(1),
          flat_rows.actions.data_ptr<float>() +
              begin * flat_rows.actions.size(1),
          rows,
          flat_rows.masks.defined() ? flat_rows.masks.data_ptr<uint8_t>() +
                                          begin * flat_rows.masks.size(1)
                                    : nullptr);
    }
    const float* log_probs = net.log_probs();
    const float* values = net.values();
    float* d_log_prob = d_log_probs(rows);
    float* d_value = d_values(rows);
    LossSums sums;
    for (int64_t i = 0; i < rows; ++i) {
      sums.policy_loss -= static_cast<double>(log_probs[i]) * adv[i];
      d_log_prob[i] = static_cast<float>(-adv[i] / count);
      const float error = values[i] - target[i];
      sums.value_loss += 0.5 * error * error;
      d_value[i] = ValueGradient(error, count);
      const float log_ratio = log_probs[i] - old_log_prob[i];
      sums.approx_kl += (std::exp(log_ratio) - 1.0f) - log_ratio;
    }
    stats.Add(FlatStep(rows, sums, std::numeric_limits<double>::quiet_NaN()));
  }
  net.Push();
  return stats.Mean();
}

AlgorithmStats A2cUpdater::AutogradUpdate(const UpdateBatch& batch,
                                          std::mt19937_64& /*rng*/) {
  const int64_t size = batch.observations.size(0);
  const int64_t rows = MinibatchRows(batch);
  MeanStats stats;
  for (int64_t begin = 0; begin + rows <= size; begin += rows) {
    // A time slice of every stream: for a recurrent policy, its chunks.
    const ChunkMinibatch minibatch =
        policy_->recurrent()
            ? ChunksOfSteps(batch, begin / batch.streams,
                            config_.steps_per_minibatch)
            : ChunkMinibatch{at::arange(begin, begin + rows, at::kLong),
                             at::Tensor()};
    const at::Tensor& index = minibatch.rows;
    const at::Tensor adv = batch.advantages.index_select(0, index);
    const at::Tensor old_log_prob =
        batch.behaviour_log_probs.index_select(0, index);
    const ChunkOutputs out = Evaluate(batch, minibatch);
    const at::Tensor log_prob =
        policy_->LogProb(out.policy, batch.actions.index_select(0, index));
    const at::Tensor error = out.values - batch.returns.index_select(0, index);
    AlgorithmStats step =
        AutogradStep(-(log_prob * adv).mean(), 0.5 * (error * error).mean(),
                     policy_->Entropy(out.policy).mean());
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

}  // namespace vantage
