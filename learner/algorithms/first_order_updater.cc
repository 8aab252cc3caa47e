#include "learner/algorithms/first_order_updater.h"

#include <ATen/ATen.h>
#include <torch/optim/optimizer.h>

#include <algorithm>
#include <utility>

#include "common/nn/distributions.h"
#include "common/util/scratch_buffer.h"
#include "learner/algorithms/gradient_step.h"

namespace vantage {

FirstOrderUpdater::FirstOrderUpdater(PolicyNetwork policy, ValueNetwork value,
                                     std::shared_ptr<ReplicaGroup> replicas,
                                     const GradientSettings& settings,
                                     const char* algorithm,
                                     std::string checkpoint_key,
                                     bool autograd_only)
    : PolicyUpdater(std::move(policy), std::move(value), std::move(replicas)),
      settings_(settings),
      checkpoint_key_(std::move(checkpoint_key)),
      parameters_(NetworkParameters(*policy_, *value_)),
      flat_(MakeFlatActorCritic(*policy_, *value_, parameters_, algorithm,
                                autograd_only)) {}

FirstOrderUpdater::~FirstOrderUpdater() = default;

void FirstOrderUpdater::UseOptimizers(
    std::unique_ptr<torch::optim::Optimizer> optimizer,
    std::unique_ptr<FlatOptimizer> flat_optimizer) {
  optimizer_ = std::move(optimizer);
  flat_optimizer_ = std::move(flat_optimizer);
}

AlgorithmStats FirstOrderUpdater::Update(const UpdateBatch& batch,
                                         double progress,
                                         std::mt19937_64& rng) {
  SetLearningRate(*optimizer_,
                  settings_.learning_rate * std::max(0.0, 1.0 - progress));
  return flat() ? FlatUpdate(batch, rng) : AutogradUpdate(batch, rng);
}

FirstOrderUpdater::FlatRows FirstOrderUpdater::StartFlatUpdate(
    const UpdateBatch& batch) {
  flat_->Pull();
  const int64_t size = batch.observations.size(0);
  FlatRows rows;
  rows.inputs = flat_->Inputs(batch.observations);
  rows.actions = FloatRows(batch.actions, size);
  rows.behaviour = FloatRows(batch.behaviour_log_probs, size);
  rows.advantages = FloatRows(batch.advantages, size);
  rows.returns = FloatRows(batch.returns, size);
  if (batch.action_masks.defined()) {
    rows.masks = batch.action_masks.to(at::kByte).contiguous();
  }
  if (batch.seq_len > 0) {
    rows.starts = batch.starts.to(at::kByte).contiguous();
    rows.states = FloatRows(batch.chunk_states, batch.chunk_states.size(0));
    rows.seq_len = batch.seq_len;
  }
  return rows;
}

FirstOrderUpdater::Gathered FirstOrderUpdater::GatherAndForward(
    const FlatRows& rows, const ChunkMinibatch& minibatch) {
  const int64_t count = minibatch.rows.size(0);
  const int64_t* index = minibatch.rows.data_ptr<int64_t>();
  GatherRows(rows.inputs.data_ptr<float>(), rows.inputs.size(1), index, count,
             inputs_);
  GatherRows(rows.actions.data_ptr<float>(), rows.actions.size(1), index, count,
             actions_);
  GatherRows(rows.behaviour.data_ptr<float>(), 1, index, count, behaviour_);
  GatherRows(rows.advantages.data_ptr<float>(), 1, index, count, advantages_);
  GatherRows(rows.returns.data_ptr<float>(), 1, index, count, returns_);
  const uint8_t* masks = nullptr;
  if (rows.masks.defined()) {
    const int64_t n = rows.masks.size(1);
    const uint8_t* all = rows.masks.data_ptr<uint8_t>();
    uint8_t* gathered = GrowScratch(masks_, count * n);
    for (int64_t r = 0; r < count; ++r) {
      std::copy_n(all + index[r] * n, n, gathered + r * n);
    }
    masks = gathered;
  }
  if (minibatch.chunks.defined()) {
    const int64_t chunks = minibatch.chunks.size(0);
    const uint8_t* starts = rows.starts.data_ptr<uint8_t>();
    uint8_t* gathered = GrowScratch(starts_, count);
    for (int64_t r = 0; r < count; ++r) gathered[r] = starts[index[r]];
    GatherRows(rows.states.data_ptr<float>(), rows.states.size(1),
               minibatch.chunks.data_ptr<int64_t>(), chunks, states_);
    flat_->ForwardSequences(inputs_.data(), actions_.data(), gathered,
                            states_.data(), rows.seq_len, chunks, masks);
  } else {
    flat_->Forward(inputs_.data(), actions_.data(), count, masks);
  }
  return Gathered{count, behaviour_.data(), advantages_.data(),
                  returns_.data()};
}

ChunkOutputs FirstOrderUpdater::Evaluate(const UpdateBatch& batch,
                                         const ChunkMinibatch& minibatch) {
  ChunkOutputs out;
  if (minibatch.chunks.defined()) {
    out = RunChunks(*policy_, *value_, batch, minibatch);
  } else {
    const at::Tensor observations =
        batch.observations.index_select(0, minibatch.rows);
    out = ChunkOutputs{policy_->forward(observations),
                       value_->forward(observations)};
  }
  if (batch.action_masks.defined()) {
    out.policy = MaskLogits(out.policy,
                            batch.action_masks.index_select(0, minibatch.rows));
  }
  return out;
}

float* FirstOrderUpdater::d_log_probs(int64_t rows) {
  d_log_probs_.resize(rows);
  return d_log_probs_.data();
}

float* FirstOrderUpdater::d_values(int64_t rows) {
  d_values_.resize(rows);
  return d_values_.data();
}

AlgorithmStats FirstOrderUpdater::FlatStep(int64_t rows, const LossSums& sums,
                                           double clip_fraction) {
  FlatActorCritic& net = *flat_;
  net.Backward(d_log_probs_.data(), -settings_.entropy_coef, d_values_.data());
  AlgorithmStats step;
  step.max_gradient_norm = AverageAndClipFlatGradient(
      net.gradients(), net.size(), settings_.max_grad_norm, *replicas_);
  flat_optimizer_->Step(*optimizer_, net.parameters(), net.gradients());
  const double count = static_cast<double>(rows);
  step.policy_loss = sums.policy_loss / count;
  step.value_loss = sums.value_loss / count;
  step.entropy = net.mean_entropy();
  step.approx_kl = sums.approx_kl / count;
  step.clip_fraction = clip_fraction;
  return step;
}

AlgorithmStats FirstOrderUpdater::AutogradStep(const at::Tensor& policy_loss,
                                               const at::Tensor& value_loss,
                                               const at::Tensor& entropy) {
  AlgorithmStats step;
  step.max_gradient_norm =
      GradientStep(*optimizer_, parameters_,
                   policy_loss + settings_.value_coef * value_loss -
                       settings_.entropy_coef * entropy,
                   settings_.max_grad_norm, *replicas_);
  step.policy_loss = policy_loss.item<double>();
  step.value_loss = value_loss.item<double>();
  step.entropy = entropy.item<double>();
  return step;
}

void FirstOrderUpdater::Save(torch::serialize::OutputArchive& archive) const {
  if (flat_optimizer_ != nullptr) flat_optimizer_->StoreInto(*optimizer_);
  SaveOptimizer(*optimizer_, checkpoint_key_, archive);
}

absl::Status FirstOrderUpdater::Load(torch::serialize::InputArchive& archive) {
  if (absl::Status status =
          LoadOptimizer(*optimizer_, checkpoint_key_, archive);
      !status.ok() || flat_optimizer_ == nullptr) {
    return status;
  }
  return flat_optimizer_->LoadFrom(*optimizer_);
}

}  // namespace vantage
