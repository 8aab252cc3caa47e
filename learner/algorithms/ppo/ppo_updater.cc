#include "learner/algorithms/ppo/ppo_updater.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <numeric>
#include <optional>
#include <vector>

#include "learner/algorithms/gradient_step.h"
#include "learner/algorithms/ppo/ppo_objective.h"
#include "learner/parallel/replica_reductions.h"

namespace vantage {

PpoUpdater::PpoUpdater(PolicyNetwork policy, ValueNetwork value,
                       const PpoConfig& config,
                       std::shared_ptr<ReplicaGroup> replicas)
    : policy_(std::move(policy)),
      value_(std::move(value)),
      config_(config),
      replicas_(std::move(replicas)),
      parameters_(NetworkParameters(*policy_, *value_)),
      optimizer_(std::make_unique<torch::optim::Adam>(
          parameters_,
          torch::optim::AdamOptions(config.learning_rate).eps(1e-5))) {}

PpoUpdater::~PpoUpdater() = default;

AlgorithmStats PpoUpdater::Update(const UpdateBatch& batch, double progress,
                                  std::mt19937_64& rng) {
  SetLearningRate(*optimizer_,
                  config_.learning_rate * std::max(0.0, 1.0 - progress));
  const int64_t size = batch.observations.size(0);
  const int64_t minibatch = std::max<int64_t>(1, size / config_.minibatches);
  std::vector<int64_t> order(size);
  MeanStats stats;
  for (int epoch = 0; epoch < config_.epochs; ++epoch) {
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    const at::Tensor permutation = at::tensor(order, at::kLong);
    std::vector<at::Tensor> indices;
    for (int64_t begin = 0; begin + minibatch <= size; begin += minibatch) {
      indices.push_back(permutation.slice(0, begin, begin + minibatch));
    }
    // Each minibatch's advantage statistics over every replica's part of
    // it, all of the epoch's in one collective.
    std::optional<PartsNormalizer> normalizer;
    if (config_.normalize_advantages) {
      normalizer.emplace(*replicas_, batch.advantages, indices);
    }
    for (size_t part = 0; part < indices.size(); ++part) {
      const at::Tensor& index = indices[part];
      const at::Tensor obs = batch.observations.index_select(0, index);
      at::Tensor adv = batch.advantages.index_select(0, index);
      if (normalizer.has_value()) adv = normalizer->Normalize(part, adv);
      const at::Tensor output = policy_->forward(obs);
      const at::Tensor log_prob =
          policy_->LogProb(output, batch.actions.index_select(0, index));
      const PpoPolicyLoss policy_loss = PpoClippedPolicyLoss(
          log_prob, batch.behaviour_log_probs.index_select(0, index), adv,
          config_.clip);
      const at::Tensor entropy = policy_->Entropy(output).mean();
      const at::Tensor value_loss =
          ValueLoss(*value_, obs, batch.returns.index_select(0, index));
      const double gradient_norm =
          GradientStep(*optimizer_, parameters_,
                       policy_loss.loss + config_.value_coef * value_loss -
                           config_.entropy_coef * entropy,
                       config_.max_grad_norm, *replicas_);
      AlgorithmStats step;
      step.max_gradient_norm = gradient_norm;
      step.policy_loss = policy_loss.loss.item<double>();
      step.value_loss = value_loss.item<double>();
      step.entropy = entropy.item<double>();
      step.approx_kl = policy_loss.approx_kl.item<double>();
      step.clip_fraction = policy_loss.clip_fraction.item<double>();
      stats.Add(step);
    }
  }
  return stats.Mean();
}

void PpoUpdater::Save(torch::serialize::OutputArchive& archive) const {
  SaveOptimizer(*optimizer_, "adam", archive);
}

absl::Status PpoUpdater::Load(torch::serialize::InputArchive& archive) {
  return LoadOptimizer(*optimizer_, "adam", archive);
}

}  // namespace vantage
