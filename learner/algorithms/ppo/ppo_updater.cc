#include "learner/algorithms/ppo/ppo_updater.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "common/nn/distributions.h"
#include "common/util/scratch_buffer.h"
#include "learner/algorithms/flat_adam.h"
#include "learner/algorithms/gradient_step.h"
#include "learner/algorithms/ppo/ppo_objective.h"
#include "learner/parallel/replica_reductions.h"

namespace vantage {
namespace {

// An epoch's minibatch order: every row once, shuffled by `rng`.
void ShuffleRows(std::vector<int64_t>& order, std::mt19937_64& rng) {
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
}

// The index tensors of an epoch's minibatches of `order`.
std::vector<at::Tensor> MinibatchIndices(const std::vector<int64_t>& order,
                                         int64_t minibatch) {
  const at::Tensor permutation = at::tensor(order, at::kLong);
  std::vector<at::Tensor> indices;
  const int64_t size = static_cast<int64_t>(order.size());
  for (int64_t begin = 0; begin + minibatch <= size; begin += minibatch) {
    indices.push_back(permutation.slice(0, begin, begin + minibatch));
  }
  return indices;
}

}  // namespace

PpoUpdater::PpoUpdater(PolicyNetwork policy, ValueNetwork value,
                       const PpoConfig& config,
                       std::shared_ptr<ReplicaGroup> replicas,
                       bool autograd_only)
    : FirstOrderUpdater(
          std::move(policy), std::move(value), std::move(replicas),
          GradientSettings{config.learning_rate, config.value_coef,
                           config.entropy_coef, config.max_grad_norm},
          "PPO", "adam", autograd_only),
      config_(config) {
  UseOptimizers(std::make_unique<torch::optim::Adam>(
                    parameters(),
                    torch::optim::AdamOptions(config.learning_rate).eps(1e-5)),
                flat() ? std::make_unique<FlatAdam>(parameters(),
                                                    flat_networks().offsets(),
                                                    flat_networks().size())
                       : nullptr);
}

PpoUpdater::~PpoUpdater() = default;

PpoUpdater::Decoupled PpoUpdater::Decouple(const UpdateBatch& batch) {
  Decoupled out{batch, at::Tensor()};
  if (!batch.lagged) return out;
  at::NoGradGuard no_grad;
  at::Tensor proximal;
  if (policy_->recurrent()) {
    // Every chunk, its rows back in the batch's order.
    const ChunkMinibatch all = ChunksOfSteps(batch, 0, batch.horizon);
    proximal = at::empty({batch.observations.size(0)}, at::kFloat)
                   .index_copy_(0, all.rows,
                                policy_->LogProb(
                                    Evaluate(batch, all).policy,
                                    batch.actions.index_select(0, all.rows)));
  } else {
    proximal = policy_->LogProb(
        MaskLogits(policy_->forward(batch.observations), batch.action_masks),
        batch.actions);
  }
  out.weights =
      at::exp(proximal - batch.behaviour_log_probs.to(proximal.dtype()));
  out.batch.behaviour_log_probs = proximal;
  return out;
}

AlgorithmStats PpoUpdater::FlatUpdate(const UpdateBatch& lagged,
                                      std::mt19937_64& rng) {
  const Decoupled decoupled = Decouple(lagged);
  const UpdateBatch& batch = decoupled.batch;
  const FlatRows rows = StartFlatUpdate(batch);
  const int64_t size = batch.observations.size(0);
  const int64_t minibatch = std::max<int64_t>(1, size / config_.minibatches);
  const at::Tensor weights = decoupled.weights.defined()
                                 ? FloatRows(decoupled.weights, size)
                                 : at::Tensor();
  std::vector<int64_t> order(size);
  MeanStats stats;
  for (int epoch = 0; epoch < config_.epochs; ++epoch) {
    const std::vector<ChunkMinibatch> minibatches =
        EpochMinibatches(batch, order, minibatch, rng);
    std::optional<PartsNormalizer> normalizer;
    if (config_.normalize_advantages) {
      std::vector<at::Tensor> parts;
      if (replicas_->world_size() > 1) {
        for (const ChunkMinibatch& m : minibatches) parts.push_back(m.rows);
      }
      normalizer.emplace(*replicas_, batch.advantages, parts);
    }
    for (size_t part = 0; part < minibatches.size(); ++part) {
      stats.Add(FlatMinibatch(rows, weights, minibatches[part],
                              normalizer.has_value() ? &*normalizer : nullptr,
                              part));
    }
  }
  flat_networks().Push();
  return stats.Mean();
}

AlgorithmStats PpoUpdater::FlatMinibatch(const FlatRows& rows,
                                         const at::Tensor& weights,
                                         const ChunkMinibatch& chunk_minibatch,
                                         PartsNormalizer* normalizer,
                                         size_t part) {
  const Gathered gathered = GatherAndForward(rows, chunk_minibatch);
  const int64_t minibatch = gathered.rows;
  float* advantages = gathered.advantages;
  if (normalizer != nullptr) {
    normalizer->NormalizeInPlace(part, advantages, minibatch);
  }
  if (weights.defined()) {
    GatherRows(weights.data_ptr<float>(), 1,
               chunk_minibatch.rows.data_ptr<int64_t>(), minibatch, weights_);
    for (int64_t i = 0; i < minibatch; ++i) advantages[i] *= weights_[i];
  }
  FlatActorCritic& net = flat_networks();
  const float* log_probs = net.log_probs();
  const float* values = net.values();
  float* d_log_prob = d_log_probs(minibatch);
  float* d_value = d_values(minibatch);
  // The clipping bounds and tests in float, as the autograd path has them.
  const float low = static_cast<float>(1.0 - config_.clip);
  const float high = static_cast<float>(1.0 + config_.clip);
  const float clip = static_cast<float>(config_.clip);
  const double count = static_cast<double>(minibatch);
  LossSums sums;
  int64_t clipped = 0;
  for (int64_t i = 0; i < minibatch; ++i) {
    const float log_ratio = log_probs[i] - gathered.behaviour[i];
    const float ratio = std::exp(log_ratio);
    const float advantage = advantages[i];
    const float unclipped = ratio * advantage;
    const float bounded = std::min(std::max(ratio, low), high) * advantage;
    // The surrogate's gradient flows through the unclipped term when it is
    // the smaller (or both are equal: the ratio is in bounds); the clipped
    // one is flat in the ratio.
    sums.policy_loss -= std::min(unclipped, bounded);
    d_log_prob[i] = unclipped <= bounded
                        ? static_cast<float>(-advantage * ratio / count)
                        : 0.0f;
    const float error = values[i] - gathered.returns[i];
    sums.value_loss += 0.5 * error * error;
    d_value[i] = ValueGradient(error, count);
    sums.approx_kl += (ratio - 1.0f) - log_ratio;
    if (std::abs(ratio - 1.0f) > clip) ++clipped;
  }
  return FlatStep(minibatch, sums, static_cast<double>(clipped) / count);
}

std::vector<ChunkMinibatch> PpoUpdater::EpochMinibatches(
    const UpdateBatch& batch, std::vector<int64_t>& order, int64_t minibatch,
    std::mt19937_64& rng) {
  if (policy_->recurrent()) {
    return ShuffledChunkMinibatches(batch, config_.minibatches, rng);
  }
  ShuffleRows(order, rng);
  std::vector<ChunkMinibatch> minibatches;
  for (const at::Tensor& rows : MinibatchIndices(order, minibatch)) {
    minibatches.push_back(ChunkMinibatch{rows, at::Tensor()});
  }
  return minibatches;
}

AlgorithmStats PpoUpdater::AutogradUpdate(const UpdateBatch& lagged,
                                          std::mt19937_64& rng) {
  const Decoupled decoupled = Decouple(lagged);
  const UpdateBatch& batch = decoupled.batch;
  const int64_t size = batch.observations.size(0);
  const int64_t minibatch = std::max<int64_t>(1, size / config_.minibatches);
  std::vector<int64_t> order(size);
  MeanStats stats;
  for (int epoch = 0; epoch < config_.epochs; ++epoch) {
    const std::vector<ChunkMinibatch> minibatches =
        EpochMinibatches(batch, order, minibatch, rng);
    std::vector<at::Tensor> indices;
    for (const ChunkMinibatch& m : minibatches) indices.push_back(m.rows);
    // Each minibatch's advantage statistics over every replica's part of
    // it, all of the epoch's in one collective.
    std::optional<PartsNormalizer> normalizer;
    if (config_.normalize_advantages) {
      normalizer.emplace(*replicas_, batch.advantages, indices);
    }
    for (size_t part = 0; part < indices.size(); ++part) {
      const at::Tensor& index = indices[part];
      at::Tensor adv = batch.advantages.index_select(0, index);
      if (normalizer.has_value()) adv = normalizer->Normalize(part, adv);
      if (decoupled.weights.defined()) {
        adv = adv * decoupled.weights.index_select(0, index);
      }
      const ChunkOutputs out = Evaluate(batch, minibatches[part]);
      const at::Tensor log_prob =
          policy_->LogProb(out.policy, batch.actions.index_select(0, index));
      const PpoPolicyLoss policy_loss = PpoClippedPolicyLoss(
          log_prob, batch.behaviour_log_probs.index_select(0, index), adv,
          config_.clip);
      const at::Tensor error =
          out.values - batch.returns.index_select(0, index);
      AlgorithmStats step =
          AutogradStep(policy_loss.loss, 0.5 * (error * error).mean(),
                       policy_->Entropy(out.policy).mean());
      step.approx_kl = policy_loss.approx_kl.item<double>();
      step.clip_fraction = policy_loss.clip_fraction.item<double>();
      stats.Add(step);
    }
  }
  return stats.Mean();
}

}  // namespace vantage
