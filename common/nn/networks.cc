#include "common/nn/networks.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>

#include "absl/strings/str_cat.h"
#include "common/nn/distributions.h"

namespace vantage {

namespace {

// The torso's convolutions (registered first, so that an MLP network's
// parameters keep their order) and the MLP after them: for images the
// MLP is just the output layer. `shared`, if not empty, is used as the
// convolutions instead of new ones.
TanhMlp MakeBody(torch::nn::Module& network, const EnvSpec& spec,
                 const NetworkConfig& config, int64_t outputs,
                 double output_gain, ConvTorso& conv, DictTorso& dict,
                 ConvTorso shared = nullptr) {
  if (!spec.observation_keys.empty()) {
    // The entries' features, then the MLP's hidden layers.
    dict = network.register_module("dict", DictTorso(spec));
    return network.register_module(
        "body", TanhMlp(dict->features(), config.hidden, outputs, output_gain));
  }
  if (shared.is_empty()) {
    const Torso torso = ResolveTorso(config.torso, spec).value();
    if (torso == Torso::kMlp) {
      return network.register_module(
          "body",
          TanhMlp(spec.observation_size, config.hidden, outputs, output_gain));
    }
    shared = ConvTorso(torso, spec.observation_shape);
  }
  conv = network.register_module("conv", std::move(shared));
  return network.register_module(
      "body",
      TanhMlp(conv->features(), std::vector<int64_t>{}, outputs, output_gain));
}

at::Tensor Forward(const EnvSpec& spec, ConvTorso& conv, DictTorso& dict,
                   TanhMlp& body, const at::Tensor& observations) {
  at::Tensor inputs = NetworkInputs(spec, observations);
  if (!conv.is_empty()) inputs = conv->forward(inputs);
  if (!dict.is_empty()) inputs = dict->forward(inputs);
  return body->forward(inputs);
}

EnvSpec FlatSpec(int64_t observation_size) {
  EnvSpec spec;
  spec.observation_size = observation_size;
  return spec;
}

}  // namespace

at::Tensor NetworkInputs(const EnvSpec& spec, const at::Tensor& observations) {
  if (observations.scalar_type() != at::kByte) return observations;
  return observations.to(at::kFloat)
      .mul_(1.0 /
            static_cast<double>(std::max<int64_t>(spec.observation_high, 1)));
}

at::Tensor ObservationTensor(const EnvSpec& spec, const double* values,
                             int64_t rows) {
  return at::from_blob(const_cast<double*>(values),
                       {rows, spec.observation_size}, at::kDouble)
      .to(spec.byte_observations() ? at::kByte : at::kFloat);
}

at::Tensor ObservationsForNetwork(const EnvSpec& spec,
                                  const RunningMeanStd& normalizer,
                                  const at::Tensor& observations, double clip) {
  if (spec.byte_observations()) return observations;
  const at::Tensor normalized = normalizer.Normalize(observations, clip);
  if (spec.observation_keys.empty()) return normalized;
  // A Dict's images are not normalised: they enter divided by their high.
  std::vector<at::Tensor> parts;
  int64_t offset = 0;
  for (const ObservationKey& key : spec.observation_keys) {
    parts.push_back(key.image()
                        ? observations.slice(1, offset, offset + key.size)
                                  .to(normalized.scalar_type()) /
                              static_cast<double>(key.high)
                        : normalized.slice(1, offset, offset + key.size));
    offset += key.size;
  }
  return at::cat(parts, 1);
}

PolicyNetworkImpl::PolicyNetworkImpl(const EnvSpec& spec,
                                     const NetworkConfig& config)
    : spec_(spec), discrete_(spec.discrete), heads_(spec.action_heads()) {
  if (config.recurrent()) {
    trunk_ = register_module("trunk", RecurrentTrunk(spec, config));
    body_ = register_module("body",
                            TanhMlp(trunk_->features(), std::vector<int64_t>{},
                                    spec.action_size, /*output_gain=*/0.01));
  } else {
    body_ = MakeBody(*this, spec, config, spec.action_size,
                     /*output_gain=*/0.01, conv_, dict_);
  }
  if (!discrete_) {
    log_std_ = register_parameter("log_std", at::zeros({spec.action_size}));
  }
}

at::Tensor PolicyNetworkImpl::forward(const at::Tensor& observations) {
  TORCH_CHECK(!recurrent(), "a recurrent policy acts with its state");
  return Forward(spec_, conv_, dict_, body_, observations);
}

at::Tensor PolicyNetworkImpl::Head(const at::Tensor& features) {
  return body_->forward(features);
}

at::Tensor PolicyNetworkImpl::Step(const at::Tensor& observations,
                                   at::Tensor& state) {
  state = trunk_->Step(trunk_->Encode(observations), state);
  return Head(trunk_->Hidden(state));
}

at::Tensor PolicyNetworkImpl::Unroll(const at::Tensor& observations,
                                     const at::Tensor& starts,
                                     const at::Tensor& state) {
  return Head(trunk_->Unroll(observations, starts, state));
}

std::vector<at::Tensor> PolicyNetworkImpl::Heads(
    const at::Tensor& output) const {
  if (heads_.size() == 1) return {output};
  return output.split_with_sizes(heads_, -1);
}

at::Tensor PolicyNetworkImpl::LogProb(const at::Tensor& output,
                                      const at::Tensor& actions) {
  if (!discrete_) return DiagGaussianLogProb(output, log_std_, actions);
  if (heads_.size() == 1) {
    return CategoricalLogProb(output, actions.reshape({-1}));
  }
  // Independent heads: the action's log-probability is their sum.
  const std::vector<at::Tensor> heads = Heads(output);
  const at::Tensor values = actions.reshape({-1, HeadCount()});
  at::Tensor sum = CategoricalLogProb(heads[0], values.select(1, 0));
  for (int64_t h = 1; h < HeadCount(); ++h) {
    sum = sum + CategoricalLogProb(heads[h], values.select(1, h));
  }
  return sum;
}

at::Tensor PolicyNetworkImpl::Entropy(const at::Tensor& output) {
  if (!discrete_) return DiagGaussianEntropy(output, log_std_);
  const std::vector<at::Tensor> heads = Heads(output);
  at::Tensor sum = CategoricalEntropy(heads[0]);
  for (int64_t h = 1; h < HeadCount(); ++h) {
    sum = sum + CategoricalEntropy(heads[h]);
  }
  return sum;
}

at::Tensor PolicyNetworkImpl::Kl(const at::Tensor& old_output,
                                 const at::Tensor& old_log_std,
                                 const at::Tensor& output) {
  if (!discrete_) {
    return DiagGaussianKl(old_output, old_log_std, output, log_std_);
  }
  const std::vector<at::Tensor> old_heads = Heads(old_output);
  const std::vector<at::Tensor> heads = Heads(output);
  at::Tensor sum = CategoricalKl(old_heads[0], heads[0]);
  for (int64_t h = 1; h < HeadCount(); ++h) {
    sum = sum + CategoricalKl(old_heads[h], heads[h]);
  }
  return sum;
}

at::Tensor PolicyNetworkImpl::Act(const at::Tensor& output, bool deterministic,
                                  at::Generator generator) {
  if (discrete_) {
    // Head by head, each over every row: the order MlpPolicyKernel draws in.
    std::vector<at::Tensor> indices;
    for (const at::Tensor& head : Heads(output)) {
      indices.push_back(deterministic ? head.argmax(-1)
                                      : at::multinomial(at::softmax(head, -1),
                                                        1, false, generator)
                                            .squeeze(-1));
    }
    return at::stack(indices, -1).to(output.scalar_type());
  }
  if (deterministic) return output;
  return output + at::exp(log_std_) * at::normal(0.0, 1.0, output.sizes(),
                                                 generator, output.options());
}

ValueNetworkImpl::ValueNetworkImpl(const EnvSpec& spec,
                                   const NetworkConfig& config)
    : spec_(spec) {
  body_ = MakeBody(*this, spec, config, 1, /*output_gain=*/1.0, conv_, dict_);
}

ValueNetworkImpl::ValueNetworkImpl(const EnvSpec& spec, ConvTorso shared)
    : spec_(spec) {
  body_ = MakeBody(*this, spec, NetworkConfig(), 1, /*output_gain=*/1.0, conv_,
                   dict_, std::move(shared));
}

ValueNetworkImpl::ValueNetworkImpl(const EnvSpec& spec, RecurrentTrunk shared)
    : spec_(spec) {
  trunk_ = register_module("trunk", std::move(shared));
  body_ = register_module("body",
                          TanhMlp(trunk_->features(), std::vector<int64_t>{}, 1,
                                  /*output_gain=*/1.0));
}

ValueNetworkImpl::ValueNetworkImpl(int64_t observation_size,
                                   const NetworkConfig& config)
    : ValueNetworkImpl(FlatSpec(observation_size), config) {}

at::Tensor ValueNetworkImpl::forward(const at::Tensor& observations) {
  TORCH_CHECK(!recurrent(), "a recurrent value network needs its state");
  return Forward(spec_, conv_, dict_, body_, observations).squeeze(-1);
}

at::Tensor ValueNetworkImpl::Head(const at::Tensor& features) {
  return body_->forward(features).squeeze(-1);
}

ValueNetwork MakeValueNetwork(const EnvSpec& spec, const NetworkConfig& config,
                              const PolicyNetworkImpl& policy) {
  if (policy.recurrent()) return ValueNetwork(spec, policy.trunk());
  if (config.shared_torso) return ValueNetwork(spec, policy.conv_torso());
  return ValueNetwork(spec, config);
}

std::vector<at::Tensor> NetworkParameters(PolicyNetworkImpl& policy,
                                          ValueNetworkImpl& value) {
  std::vector<at::Tensor> parameters = policy.parameters();
  std::unordered_set<const void*> seen;
  for (const at::Tensor& p : parameters) seen.insert(p.unsafeGetTensorImpl());
  for (const at::Tensor& p : value.parameters()) {
    if (seen.insert(p.unsafeGetTensorImpl()).second) parameters.push_back(p);
  }
  return parameters;
}

}  // namespace vantage
