#include "learner/algorithms/flat_actor_critic.h"

#include <ATen/ATen.h>
#include <torch/nn/modules/linear.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/nn/distributions.h"
#include "common/nn/networks.h"
#include "common/util/scratch_buffer.h"

namespace vantage {

absl::StatusOr<FlatActorCritic> FlatActorCritic::Create(
    PolicyNetworkImpl& policy, ValueNetworkImpl& value,
    std::vector<at::Tensor> parameters) {
  if (!policy.conv_torso().is_empty() || !value.conv_torso().is_empty() ||
      !policy.dict_torso().is_empty()) {
    return absl::UnimplementedError(
        "the networks have a convolutional or Dict torso, which only "
        "autograd trains");
  }
  if (policy.recurrent() && !policy.trunk()->conv_torso().is_empty()) {
    return absl::UnimplementedError(
        "the networks' core follows a convolutional torso, which only "
        "autograd trains");
  }
  FlatActorCritic flat;
  flat.spec_ = policy.spec();
  flat.discrete_ = policy.discrete();
  flat.heads_ = policy.heads();
  absl::StatusOr<FlatParameterClaims> claims =
      FlatParameterClaims::Create(std::move(parameters));
  if (!claims.ok()) return claims.status();
  if (absl::Status status = flat.LayOutNetworks(policy, value, *claims);
      !status.ok()) {
    return status;
  }
  flat.tensors_ = claims->tensors();
  flat.offsets_ = claims->offsets();
  flat.parameters_.resize(claims->size());
  flat.gradients_.assign(claims->size(), 0.0f);
  flat.Pull();
  return flat;
}

absl::Status FlatActorCritic::LayOutNetworks(PolicyNetworkImpl& policy,
                                             ValueNetworkImpl& value,
                                             FlatParameterClaims& claims) {
  if (policy.recurrent()) {
    if (absl::Status status = LayOutRecurrent(policy, value, claims);
        !status.ok()) {
      return status;
    }
  }
  const int64_t inputs = core_ ? core_->hidden() : spec_.observation_size;
  absl::StatusOr<FlatMlp> policy_mlp =
      FlatMlp::LayOut(policy.body()->layers(), inputs, spec_.action_size,
                      /*squash_last=*/false, claims);
  if (!policy_mlp.ok()) return policy_mlp.status();
  policy_ = *std::move(policy_mlp);
  absl::StatusOr<FlatMlp> value_mlp = FlatMlp::LayOut(
      value.body()->layers(), inputs, 1, /*squash_last=*/false, claims);
  if (!value_mlp.ok()) return value_mlp.status();
  value_ = *std::move(value_mlp);
  if (!discrete_) {
    log_std_ = claims.Claim(policy.log_std());
    if (log_std_ < 0) {
      return absl::UnimplementedError("the log-std is not a given parameter");
    }
  }
  if (!claims.AllClaimed()) {
    return absl::UnimplementedError(
        "a parameter belongs to neither network's layers nor the log-std");
  }
  return absl::OkStatus();
}

absl::Status FlatActorCritic::LayOutRecurrent(PolicyNetworkImpl& policy,
                                              ValueNetworkImpl& value,
                                              FlatParameterClaims& claims) {
  if (!value.recurrent()) {
    return absl::UnimplementedError("the value network has no recurrent trunk");
  }
  const RecurrentTrunk& trunk = policy.trunk();
  int64_t width = spec_.observation_size;
  if (!trunk->encoder().is_empty()) {
    const auto& last = trunk->encoder()->layers()->at<torch::nn::LinearImpl>(
        trunk->encoder()->layers()->size() - 1);
    width = last.weight.size(0);
    absl::StatusOr<FlatMlp> encoder =
        FlatMlp::LayOut(trunk->encoder()->layers(), spec_.observation_size,
                        width, /*squash_last=*/true, claims);
    if (!encoder.ok()) return encoder.status();
    encoder_ = *std::move(encoder);
  }
  const bool lstm = trunk->core() == Core::kLstm;
  const at::Tensor& weight_ih =
      lstm ? trunk->lstm()->weight_ih : trunk->gru()->weight_ih;
  const at::Tensor& weight_hh =
      lstm ? trunk->lstm()->weight_hh : trunk->gru()->weight_hh;
  FlatRecurrentCore::Offsets offsets;
  offsets.weight_ih = claims.Claim(weight_ih);
  offsets.weight_hh = claims.Claim(weight_hh);
  offsets.bias_ih =
      claims.Claim(lstm ? trunk->lstm()->bias_ih : trunk->gru()->bias_ih);
  offsets.bias_hh =
      claims.Claim(lstm ? trunk->lstm()->bias_hh : trunk->gru()->bias_hh);
  if (offsets.weight_ih < 0 || offsets.weight_hh < 0 || offsets.bias_ih < 0 ||
      offsets.bias_hh < 0 || weight_ih.size(1) != width) {
    return absl::UnimplementedError(
        absl::StrCat("the core is not a biased cell on ", width,
                     " inputs whose parameters are the given ones"));
  }
  core_.emplace(trunk->core(), width, trunk->features(), offsets);
  return absl::OkStatus();
}

void FlatActorCritic::Pull() {
  for (size_t i = 0; i < tensors_.size(); ++i) {
    std::memcpy(parameters_.data() + offsets_[i], tensors_[i].data_ptr<float>(),
                sizeof(float) * tensors_[i].numel());
  }
}

void FlatActorCritic::Push() {
  for (size_t i = 0; i < tensors_.size(); ++i) {
    std::memcpy(tensors_[i].data_ptr<float>(), parameters_.data() + offsets_[i],
                sizeof(float) * tensors_[i].numel());
  }
}

at::Tensor FlatActorCritic::Inputs(const at::Tensor& observations) const {
  return ::vantage::NetworkInputs(spec_, observations)
      .to(at::kFloat)
      .contiguous();
}

void FlatActorCritic::Forward(const float* inputs, const float* actions,
                              int64_t rows, const uint8_t* masks) {
  rows_ = rows;
  inputs_ = inputs;
  actions_ = actions;
  policy_.Forward(parameters_.data(), inputs, rows);
  value_.Forward(parameters_.data(), inputs, rows);
  Heads(actions, masks, rows);
}

void FlatActorCritic::ForwardSequences(const float* inputs,
                                       const float* actions,
                                       const uint8_t* starts,
                                       const float* states, int64_t steps,
                                       int64_t chunks, const uint8_t* masks) {
  const int64_t rows = steps * chunks;
  rows_ = rows;
  inputs_ = inputs;
  actions_ = actions;
  const float* encoded = inputs;
  if (!encoder_.empty()) {
    encoder_.Forward(parameters_.data(), inputs, rows);
    encoded = encoder_.output();
  }
  core_->Forward(parameters_.data(), encoded, starts, states, steps, chunks);
  policy_.Forward(parameters_.data(), core_->features(), rows);
  value_.Forward(parameters_.data(), core_->features(), rows);
  Heads(actions, masks, rows);
}

void FlatActorCritic::Heads(const float* actions, const uint8_t* masks,
                            int64_t rows) {
  GrowScratch(values_, rows);
  std::memcpy(values_.data(), value_.output(), sizeof(float) * rows);
  GrowScratch(log_probs_, rows);
  if (discrete_) {
    CategoricalHead(actions, masks, rows);
  } else {
    GaussianHead(actions, rows);
  }
}

void FlatActorCritic::GaussianHead(const float* actions, int64_t rows) {
  const int64_t k = spec_.action_size;
  const float* mean = policy_.output();
  const float* log_std = parameters_.data() + log_std_;
  float* z = GrowScratch(head_, rows * k);
  const float constant = static_cast<float>(kLogSqrtTwoPi);
  for (int64_t r = 0; r < rows; ++r) {
    float sum = 0.0f;
    for (int64_t j = 0; j < k; ++j) {
      const int64_t i = r * k + j;
      z[i] = (actions[i] - mean[i]) * std::exp(-log_std[j]);
      sum += -0.5f * z[i] * z[i] - log_std[j] - constant;
    }
    log_probs_[r] = sum;
  }
  double entropy = 0.0;
  for (int64_t j = 0; j < k; ++j) entropy += log_std[j] + kLogSqrtTwoPi + 0.5;
  mean_entropy_ = entropy;
}

void FlatActorCritic::CategoricalHead(const float* actions,
                                      const uint8_t* masks, int64_t rows) {
  const int64_t n = spec_.action_size;
  const int64_t width = static_cast<int64_t>(heads_.size());
  // The policy layer's outputs are not read again by Backward (no tanh
  // after it), so the masked logits replace them; an illegal action's
  // probability is then 0 and so is every gradient through its logit.
  float* logits = policy_.output();
  if (masks != nullptr) MaskLogitsInPlace(logits, masks, rows, n);
  float* log_p = GrowScratch(head_, rows * n);
  float* entropies = GrowScratch(entropies_, rows * width);
  double entropy_sum = 0.0;
  for (int64_t r = 0; r < rows; ++r) {
    float log_prob = 0.0f;
    int64_t offset = 0;
    // Independent heads (one for Discrete): log-probabilities and
    // entropies sum over them.
    for (int64_t h = 0; h < width; offset += heads_[h], ++h) {
      const int64_t choices = heads_[h];
      const float* row = logits + r * n + offset;
      float* out = log_p + r * n + offset;
      const float max = *std::max_element(row, row + choices);
      float sum = 0.0f;
      for (int64_t j = 0; j < choices; ++j) sum += std::exp(row[j] - max);
      const float log_sum = std::log(sum) + max;
      float entropy = 0.0f;
      for (int64_t j = 0; j < choices; ++j) {
        out[j] = row[j] - log_sum;
        entropy -= std::exp(out[j]) * out[j];
      }
      entropies[r * width + h] = entropy;
      entropy_sum += entropy;
      // Ingest refuses such actions; should one slip through, the update's
      // loss turns non-finite and the learner's guard undoes it.
      const int64_t action = static_cast<int64_t>(actions[r * width + h]);
      log_prob += action >= 0 && action < choices
                      ? out[action]
                      : std::numeric_limits<float>::quiet_NaN();
    }
    log_probs_[r] = log_prob;
  }
  mean_entropy_ = entropy_sum / static_cast<double>(std::max<int64_t>(rows, 1));
}

void FlatActorCritic::Backward(const float* d_log_probs, double entropy_weight,
                               const float* d_values) {
  const int64_t rows = rows_;
  const int64_t k = spec_.action_size;
  float* d_output = GrowScratch(policy_gradient_, rows * k);
  if (discrete_) {
    const float* log_p = head_.data();
    const int64_t width = static_cast<int64_t>(heads_.size());
    // In head h: d entropy_rh / d logit_j = -p_j (log p_j + entropy_rh),
    // and d log_prob_r / d logit_j = [j is the head's action] - p_j.
    const float per_row = static_cast<float>(
        entropy_weight / static_cast<double>(std::max<int64_t>(rows, 1)));
    for (int64_t r = 0; r < rows; ++r) {
      int64_t offset = 0;
      for (int64_t h = 0; h < width; offset += heads_[h], ++h) {
        const int64_t action =
            offset + static_cast<int64_t>(actions_[r * width + h]);
        const float entropy = entropies_[r * width + h];
        for (int64_t j = offset; j < offset + heads_[h]; ++j) {
          const int64_t i = r * k + j;
          const float p = std::exp(log_p[i]);
          d_output[i] = d_log_probs[r] * ((j == action ? 1.0f : 0.0f) - p) -
                        per_row * p * (log_p[i] + entropy);
        }
      }
    }
  } else {
    // d log_prob / d mean_j = z_j / std_j; d log_prob / d log_std_j =
    // z_j^2 - 1; the mean entropy grows by one per unit of each log-std.
    const float* z = head_.data();
    const float* log_std = parameters_.data() + log_std_;
    float* d_log_std = gradients_.data() + log_std_;
    for (int64_t j = 0; j < k; ++j) {
      d_log_std[j] = static_cast<float>(entropy_weight);
    }
    for (int64_t j = 0; j < k; ++j) {
      const float inverse_std = std::exp(-log_std[j]);
      float sum = 0.0f;
      for (int64_t r = 0; r < rows; ++r) {
        const float zi = z[r * k + j];
        d_output[r * k + j] = d_log_probs[r] * zi * inverse_std;
        sum += d_log_probs[r] * (zi * zi - 1.0f);
      }
      d_log_std[j] += sum;
    }
  }
  float* d_value = GrowScratch(value_gradient_, rows);
  std::memcpy(d_value, d_values, sizeof(float) * rows);
  if (core_) {
    TrunkBackward(rows);
    return;
  }
  policy_.Backward(parameters_.data(), gradients_.data(), inputs_, rows,
                   policy_gradient_);
  value_.Backward(parameters_.data(), gradients_.data(), inputs_, rows,
                  value_gradient_);
}

void FlatActorCritic::TrunkBackward(int64_t rows) {
  const int64_t h = core_->hidden();
  const float* features = core_->features();
  float* d_features = GrowScratch(d_features_, rows * h);
  float* d_value_features = GrowScratch(d_value_features_, rows * h);
  policy_.Backward(parameters_.data(), gradients_.data(), features, rows,
                   policy_gradient_, d_features);
  value_.Backward(parameters_.data(), gradients_.data(), features, rows,
                  value_gradient_, d_value_features);
  for (int64_t i = 0; i < rows * h; ++i) d_features[i] += d_value_features[i];
  const int64_t width = core_->inputs();
  float* d_encoded = GrowScratch(d_encoded_, rows * width);
  core_->Backward(parameters_.data(), d_features, gradients_.data(), d_encoded);
  if (encoder_.empty()) return;
  // Through the encoder's last tanh, then its layers.
  const float* encoded = encoder_.output();
  for (int64_t i = 0; i < rows * width; ++i) {
    d_encoded[i] *= 1.0f - encoded[i] * encoded[i];
  }
  encoder_.Backward(parameters_.data(), gradients_.data(), inputs_, rows,
                    d_encoded_);
}

}  // namespace vantage
