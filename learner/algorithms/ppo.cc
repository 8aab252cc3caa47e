#include "learner/algorithms/ppo.h"

#include <ATen/ATen.h>
#include <torch/nn/utils/clip_grad.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "absl/strings/str_cat.h"
#include "learner/algorithms/ppo_objective.h"

namespace vantage {

absl::Status PpoConfig::Validate() const {
  if (epochs < 1) return absl::InvalidArgumentError("ppo epochs must be >= 1");
  if (minibatches < 1) {
    return absl::InvalidArgumentError("ppo minibatches must be >= 1");
  }
  if (!(clip > 0 && clip < 1)) {
    return absl::InvalidArgumentError("ppo clip must be in (0, 1)");
  }
  if (!(learning_rate > 0)) {
    return absl::InvalidArgumentError("ppo learning rate must be > 0");
  }
  if (!(max_grad_norm > 0)) {
    return absl::InvalidArgumentError("ppo max_grad_norm must be > 0");
  }
  return absl::OkStatus();
}

PpoUpdater::PpoUpdater(PolicyNetwork policy, ValueNetwork value,
                       const PpoConfig& config)
    : policy_(std::move(policy)), value_(std::move(value)), config_(config) {
  for (const at::Tensor& p : policy_->parameters()) parameters_.push_back(p);
  for (const at::Tensor& p : value_->parameters()) parameters_.push_back(p);
  optimizer_ = std::make_unique<torch::optim::Adam>(
      parameters_, torch::optim::AdamOptions(config_.learning_rate).eps(1e-5));
}

PpoStats PpoUpdater::Update(const at::Tensor& observations,
                            const at::Tensor& actions,
                            const at::Tensor& behaviour_log_probs,
                            const at::Tensor& advantages,
                            const at::Tensor& returns, double learning_rate,
                            std::mt19937_64& rng) {
  for (auto& group : optimizer_->param_groups()) {
    static_cast<torch::optim::AdamOptions&>(group.options()).lr(learning_rate);
  }
  const int64_t batch = observations.size(0);
  const int64_t minibatch = std::max<int64_t>(1, batch / config_.minibatches);
  std::vector<int64_t> order(batch);
  PpoStats stats;
  int64_t count = 0;
  for (int epoch = 0; epoch < config_.epochs; ++epoch) {
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    const at::Tensor permutation = at::tensor(order, at::kLong);
    for (int64_t begin = 0; begin + minibatch <= batch; begin += minibatch) {
      const at::Tensor index = permutation.slice(0, begin, begin + minibatch);
      const at::Tensor obs = observations.index_select(0, index);
      at::Tensor adv = advantages.index_select(0, index);
      if (config_.normalize_advantages) {
        adv = (adv - adv.mean()) / (adv.std() + 1e-8);
      }
      const at::Tensor output = policy_->forward(obs);
      const at::Tensor log_prob =
          policy_->LogProb(output, actions.index_select(0, index));
      const PpoPolicyLoss policy_loss = PpoClippedPolicyLoss(
          log_prob, behaviour_log_probs.index_select(0, index), adv,
          config_.clip);
      const at::Tensor entropy = policy_->Entropy(output).mean();
      const at::Tensor value_error =
          value_->forward(obs) - returns.index_select(0, index);
      const at::Tensor value_loss = 0.5 * (value_error * value_error).mean();
      const at::Tensor loss = policy_loss.loss +
                              config_.value_coef * value_loss -
                              config_.entropy_coef * entropy;
      optimizer_->zero_grad();
      loss.backward();
      torch::nn::utils::clip_grad_norm_(parameters_, config_.max_grad_norm);
      optimizer_->step();
      stats.policy_loss += policy_loss.loss.item<double>();
      stats.value_loss += value_loss.item<double>();
      stats.entropy += entropy.item<double>();
      stats.approx_kl += policy_loss.approx_kl.item<double>();
      stats.clip_fraction += policy_loss.clip_fraction.item<double>();
      ++count;
    }
  }
  if (count > 0) {
    stats.policy_loss /= count;
    stats.value_loss /= count;
    stats.entropy /= count;
    stats.approx_kl /= count;
    stats.clip_fraction /= count;
  }
  return stats;
}

}  // namespace vantage
