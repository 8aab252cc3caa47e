#include "learner/algorithms/gradient_step.h"

#include <ATen/ATen.h>
#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/optimizer.h>
#include <torch/serialize/archive.h>

#include <cmath>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "learner/archive_io.h"
#include "learner/parallel/replica_reductions.h"

namespace vantage {

at::Tensor ValueLoss(ValueNetworkImpl& value, const at::Tensor& observations,
                     const at::Tensor& targets) {
  const at::Tensor error = value.forward(observations) - targets;
  return 0.5 * (error * error).mean();
}

double GradientStep(torch::optim::Optimizer& optimizer,
                    const std::vector<at::Tensor>& parameters,
                    const at::Tensor& loss, double max_grad_norm,
                    ReplicaGroup& replicas) {
  optimizer.zero_grad();
  loss.backward();
  AverageGradients(replicas, parameters);
  const double norm =
      torch::nn::utils::clip_grad_norm_(parameters, max_grad_norm);
  optimizer.step();
  return norm;
}

double AverageAndClipFlatGradient(float* gradients, int64_t size,
                                  double max_grad_norm,
                                  ReplicaGroup& replicas) {
  if (replicas.world_size() > 1) {
    std::vector<at::Tensor> flat = {at::from_blob(gradients, {size})};
    replicas.AllReduceSum(flat);
    flat[0].div_(replicas.world_size());
  }
  double squares = 0.0;
  for (int64_t i = 0; i < size; ++i) {
    squares += static_cast<double>(gradients[i]) * gradients[i];
  }
  const double norm = std::sqrt(squares);
  // In float, as clip_grad_norm_ computes the coefficient on its float norm.
  const float coefficient =
      static_cast<float>(max_grad_norm / (static_cast<float>(norm) + 1e-6));
  if (coefficient < 1.0f) {
    for (int64_t i = 0; i < size; ++i) gradients[i] *= coefficient;
  }
  return norm;
}

std::optional<FlatActorCritic> MakeFlatActorCritic(
    PolicyNetworkImpl& policy, ValueNetworkImpl& value,
    const std::vector<at::Tensor>& parameters, const char* algorithm,
    bool autograd_only) {
  if (autograd_only) return std::nullopt;
  absl::StatusOr<FlatActorCritic> flat =
      FlatActorCritic::Create(policy, value, parameters);
  if (!flat.ok()) {
    std::fprintf(stderr, "learner: %s updates run on autograd: %s\n", algorithm,
                 std::string(flat.status().message()).c_str());
    return std::nullopt;
  }
  return std::move(*flat);
}

at::Tensor FloatRows(const at::Tensor& values, int64_t rows) {
  return values.detach().to(at::kFloat).contiguous().reshape({rows, -1});
}

void SetLearningRate(torch::optim::Optimizer& optimizer, double learning_rate) {
  for (auto& group : optimizer.param_groups()) {
    group.options().set_lr(learning_rate);
  }
}

void MeanStats::Add(const AlgorithmStats& stats) {
  sum_.policy_loss += stats.policy_loss;
  sum_.value_loss += stats.value_loss;
  sum_.entropy += stats.entropy;
  sum_.approx_kl += stats.approx_kl;
  sum_.clip_fraction += stats.clip_fraction;
  // A NaN norm must stick, which std::max does not guarantee.
  const double norm = stats.max_gradient_norm;
  if (count_ == 0 || std::isnan(norm) || norm > sum_.max_gradient_norm) {
    sum_.max_gradient_norm = norm;
  }
  ++count_;
}

AlgorithmStats MeanStats::Mean() const {
  if (count_ == 0) return AlgorithmStats();
  AlgorithmStats mean = sum_;
  for (double* field : {&mean.policy_loss, &mean.value_loss, &mean.entropy,
                        &mean.approx_kl, &mean.clip_fraction}) {
    *field /= count_;
  }
  return mean;
}

void SaveOptimizer(const torch::optim::Optimizer& optimizer,
                   const std::string& key,
                   torch::serialize::OutputArchive& archive) {
  torch::serialize::OutputArchive state;
  optimizer.save(state);
  archive.write(key, state);
}

absl::Status LoadOptimizer(torch::optim::Optimizer& optimizer,
                           const std::string& key,
                           torch::serialize::InputArchive& archive) {
  return CatchTorchErrors(
      absl::StrCat("optimiser state '", key, "' is missing or does not fit"),
      [&] {
        torch::serialize::InputArchive state;
        archive.read(key, state);
        optimizer.load(state);
      });
}

}  // namespace vantage
