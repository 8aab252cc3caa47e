#include "learner/algorithms/ppo/ppo_updater.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "common/util/scratch_buffer.h"
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

// `rows` rows of `width` floats of `source` picked by `index` into `out`.
void GatherRows(const float* source, int64_t width, const int64_t* index,
                int64_t rows, std::vector<float>& out) {
  float* target = GrowScratch(out, rows * width);
  for (int64_t r = 0; r < rows; ++r) {
    std::copy(source + index[r] * width, source + (index[r] + 1) * width,
              target + r * width);
  }
}

}  // namespace

PpoUpdater::PpoUpdater(PolicyNetwork policy, ValueNetwork value,
                       const PpoConfig& config,
                       std::shared_ptr<ReplicaGroup> replicas,
                       bool autograd_only)
    : policy_(std::move(policy)),
      value_(std::move(value)),
      config_(config),
      replicas_(std::move(replicas)),
      parameters_(NetworkParameters(*policy_, *value_)),
      optimizer_(std::make_unique<torch::optim::Adam>(
          parameters_,
          torch::optim::AdamOptions(config.learning_rate).eps(1e-5))),
      flat_(MakeFlatActorCritic(*policy_, *value_, parameters_, "PPO",
                                autograd_only)) {
  if (flat_.has_value()) {
    flat_adam_.emplace(parameters_, flat_->offsets(), flat_->size());
  }
}

PpoUpdater::~PpoUpdater() = default;

AlgorithmStats PpoUpdater::Update(const UpdateBatch& batch, double progress,
                                  std::mt19937_64& rng) {
  SetLearningRate(*optimizer_,
                  config_.learning_rate * std::max(0.0, 1.0 - progress));
  const Decoupled decoupled = Decouple(batch);
  return flat_.has_value() ? FlatUpdate(decoupled, rng)
                           : AutogradUpdate(decoupled, rng);
}

PpoUpdater::Decoupled PpoUpdater::Decouple(const UpdateBatch& batch) {
  Decoupled out{batch, at::Tensor()};
  if (!batch.lagged) return out;
  at::NoGradGuard no_grad;
  const at::Tensor proximal =
      policy_->LogProb(policy_->forward(batch.observations), batch.actions);
  out.weights =
      at::exp(proximal - batch.behaviour_log_probs.to(proximal.dtype()));
  out.batch.behaviour_log_probs = proximal;
  return out;
}

AlgorithmStats PpoUpdater::FlatUpdate(const Decoupled& decoupled,
                                      std::mt19937_64& rng) {
  const UpdateBatch& batch = decoupled.batch;
  FlatActorCritic& net = *flat_;
  // The modules may have been rolled back or loaded since the last update.
  net.Pull();
  const int64_t size = batch.observations.size(0);
  const int64_t minibatch = std::max<int64_t>(1, size / config_.minibatches);
  const at::Tensor inputs = net.Inputs(batch.observations);
  const at::Tensor actions = FloatRows(batch.actions, size);
  const at::Tensor behaviour = FloatRows(batch.behaviour_log_probs, size);
  const at::Tensor advantages = FloatRows(batch.advantages, size);
  const at::Tensor returns = FloatRows(batch.returns, size);
  const at::Tensor weights = decoupled.weights.defined()
                                 ? FloatRows(decoupled.weights, size)
                                 : at::Tensor();
  const int64_t observation_size = inputs.size(1);
  const int64_t action_width = actions.size(1);
  d_log_probs_.resize(minibatch);
  d_values_.resize(minibatch);
  // The clipping bounds and tests in float, as the autograd path has them.
  const float low = static_cast<float>(1.0 - config_.clip);
  const float high = static_cast<float>(1.0 + config_.clip);
  const float clip = static_cast<float>(config_.clip);
  const double rows = static_cast<double>(minibatch);
  std::vector<int64_t> order(size);
  MeanStats stats;
  for (int epoch = 0; epoch < config_.epochs; ++epoch) {
    ShuffleRows(order, rng);
    std::optional<PartsNormalizer> normalizer;
    if (config_.normalize_advantages) {
      normalizer.emplace(*replicas_, batch.advantages,
                         replicas_->world_size() > 1
                             ? MinibatchIndices(order, minibatch)
                             : std::vector<at::Tensor>{});
    }
    size_t part = 0;
    for (int64_t begin = 0; begin + minibatch <= size;
         begin += minibatch, ++part) {
      const int64_t* index = order.data() + begin;
      GatherRows(inputs.data_ptr<float>(), observation_size, index, minibatch,
                 inputs_);
      GatherRows(actions.data_ptr<float>(), action_width, index, minibatch,
                 actions_);
      GatherRows(behaviour.data_ptr<float>(), 1, index, minibatch, behaviour_);
      GatherRows(advantages.data_ptr<float>(), 1, index, minibatch,
                 advantages_);
      GatherRows(returns.data_ptr<float>(), 1, index, minibatch, returns_);
      if (normalizer.has_value()) {
        normalizer->NormalizeInPlace(part, advantages_.data(), minibatch);
      }
      if (weights.defined()) {
        GatherRows(weights.data_ptr<float>(), 1, index, minibatch, weights_);
        for (int64_t i = 0; i < minibatch; ++i) advantages_[i] *= weights_[i];
      }
      net.Forward(inputs_.data(), actions_.data(), minibatch);
      const float* log_probs = net.log_probs();
      const float* values = net.values();
      double policy_loss = 0.0, value_loss = 0.0, approx_kl = 0.0;
      int64_t clipped = 0;
      for (int64_t i = 0; i < minibatch; ++i) {
        const float log_ratio = log_probs[i] - behaviour_[i];
        const float ratio = std::exp(log_ratio);
        const float advantage = advantages_[i];
        const float unclipped = ratio * advantage;
        const float bounded = std::min(std::max(ratio, low), high) * advantage;
        // The surrogate's gradient flows through the unclipped term when
        // it is the smaller (or both are equal: the ratio is in bounds);
        // the clipped one is flat in the ratio.
        policy_loss -= std::min(unclipped, bounded);
        d_log_probs_[i] = unclipped <= bounded
                              ? static_cast<float>(-advantage * ratio / rows)
                              : 0.0f;
        const float error = values[i] - returns_[i];
        value_loss += 0.5 * error * error;
        d_values_[i] = static_cast<float>(config_.value_coef * error / rows);
        approx_kl += (ratio - 1.0f) - log_ratio;
        if (std::abs(ratio - 1.0f) > clip) ++clipped;
      }
      net.Backward(d_log_probs_.data(), -config_.entropy_coef,
                   d_values_.data());
      AlgorithmStats step;
      step.max_gradient_norm = AverageAndClipFlatGradient(
          net.gradients(), net.size(), config_.max_grad_norm, *replicas_);
      flat_adam_->Step(*optimizer_, net.parameters(), net.gradients());
      step.policy_loss = policy_loss / rows;
      step.value_loss = value_loss / rows;
      step.entropy = net.mean_entropy();
      step.approx_kl = approx_kl / rows;
      step.clip_fraction = static_cast<double>(clipped) / rows;
      stats.Add(step);
    }
  }
  net.Push();
  return stats.Mean();
}

AlgorithmStats PpoUpdater::AutogradUpdate(const Decoupled& decoupled,
                                          std::mt19937_64& rng) {
  const UpdateBatch& batch = decoupled.batch;
  const int64_t size = batch.observations.size(0);
  const int64_t minibatch = std::max<int64_t>(1, size / config_.minibatches);
  std::vector<int64_t> order(size);
  MeanStats stats;
  for (int epoch = 0; epoch < config_.epochs; ++epoch) {
    ShuffleRows(order, rng);
    const std::vector<at::Tensor> indices = MinibatchIndices(order, minibatch);
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
      if (decoupled.weights.defined()) {
        adv = adv * decoupled.weights.index_select(0, index);
      }
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
  if (flat_adam_.has_value()) flat_adam_->StoreInto(*optimizer_);
  SaveOptimizer(*optimizer_, "adam", archive);
}

absl::Status PpoUpdater::Load(torch::serialize::InputArchive& archive) {
  if (absl::Status status = LoadOptimizer(*optimizer_, "adam", archive);
      !status.ok() || !flat_adam_.has_value()) {
    return status;
  }
  return flat_adam_->LoadFrom(*optimizer_);
}

}  // namespace vantage
