#include "learner/algorithms/gradient_step.h"

#include <ATen/ATen.h>
#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/adam.h>
#include <torch/optim/optimizer.h>
#include <torch/optim/rmsprop.h>
#include <torch/serialize/archive.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/util/scratch_buffer.h"
#include "learner/checkpoint/archive_io.h"
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

void AverageFlatGradient(float* gradients, int64_t size,
                         ReplicaGroup& replicas) {
  if (replicas.world_size() == 1) return;
  std::vector<at::Tensor> flat = {at::from_blob(gradients, {size})};
  replicas.AllReduceSum(flat);
  flat[0].div_(replicas.world_size());
}

double AverageAndClipFlatGradient(float* gradients, int64_t size,
                                  double max_grad_norm,
                                  ReplicaGroup& replicas) {
  AverageFlatGradient(gradients, size, replicas);
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

void GatherRows(const float* source, int64_t width, const int64_t* index,
                int64_t rows, std::vector<float>& out) {
  float* target = GrowScratch(out, rows * width);
  for (int64_t r = 0; r < rows; ++r) {
    std::copy(source + index[r] * width, source + (index[r] + 1) * width,
              target + r * width);
  }
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

namespace {

// The tensors of one parameter's optimiser state that must have the
// parameter's shape (those of the optimisers the learner uses; undefined
// ones, such as Adam's max_exp_avg_sq without amsgrad, are skipped).
std::vector<std::pair<const char*, at::Tensor>> ShapedState(
    const torch::optim::OptimizerParamState& state) {
  if (const auto* adam =
          dynamic_cast<const torch::optim::AdamParamState*>(&state)) {
    return {{"exp_avg", adam->exp_avg()},
            {"exp_avg_sq", adam->exp_avg_sq()},
            {"max_exp_avg_sq", adam->max_exp_avg_sq()}};
  }
  if (const auto* rmsprop =
          dynamic_cast<const torch::optim::RMSpropParamState*>(&state)) {
    return {{"square_avg", rmsprop->square_avg()},
            {"momentum_buffer", rmsprop->momentum_buffer()},
            {"grad_avg", rmsprop->grad_avg()}};
  }
  return {};
}

std::string ShapeText(at::IntArrayRef sizes) {
  std::string text = "[";
  for (size_t i = 0; i < sizes.size(); ++i) {
    absl::StrAppend(&text, i == 0 ? "" : ", ", sizes[i]);
  }
  return text + "]";
}

// LibTorch restores an optimiser's state by parameter position without
// looking at shapes, so a state saved for other networks would load and
// only fail (or silently broadcast) at the next step.
absl::Status CheckStateShapes(const torch::optim::Optimizer& optimizer,
                              const std::string& key) {
  int index = 0;
  for (const auto& group : optimizer.param_groups()) {
    for (const at::Tensor& parameter : group.params()) {
      const auto found = optimizer.state().find(
          c10::guts::to_string(parameter.unsafeGetTensorImpl()));
      if (found != optimizer.state().end()) {
        for (const auto& [name, tensor] : ShapedState(*found->second)) {
          if (tensor.defined() && tensor.sizes() != parameter.sizes()) {
            return absl::InvalidArgumentError(
                absl::StrCat("optimiser state '", key, "' does not fit: its ",
                             name, " of parameter ", index, " has shape ",
                             ShapeText(tensor.sizes()), ", the parameter ",
                             ShapeText(parameter.sizes())));
          }
        }
      }
      ++index;
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status LoadOptimizer(torch::optim::Optimizer& optimizer,
                           const std::string& key,
                           torch::serialize::InputArchive& archive) {
  // The state before, to put back when the saved one does not fit.
  std::stringstream before;
  {
    torch::serialize::OutputArchive saved;
    optimizer.save(saved);
    saved.save_to(before);
  }
  absl::Status status = CatchTorchErrors(
      absl::StrCat("optimiser state '", key, "' is missing or does not fit"),
      [&] {
        torch::serialize::InputArchive state;
        archive.read(key, state);
        optimizer.load(state);
      });
  if (status.ok()) status = CheckStateShapes(optimizer, key);
  if (!status.ok()) {
    CatchTorchErrors("the optimiser's own state", [&] {
      torch::serialize::InputArchive saved;
      saved.load_from(before);
      optimizer.load(saved);
    }).IgnoreError();  // the error to report is the first one
  }
  return status;
}

}  // namespace vantage
