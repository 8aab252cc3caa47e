#include "common/nn/policy_runner.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <ATen/core/grad_mode.h>

#include "common/nn/distributions.h"

namespace vantage {

PolicyRunner::PolicyRunner(const EnvSpec& spec, const NetworkConfig& network,
                           double observation_clip)
    : spec_(spec),
      policy_(spec, network),
      normalizer_(spec.observation_size),
      observation_clip_(observation_clip),
      generator_(at::detail::createCPUGenerator(0)) {
  StartEpisode();
}

absl::Status PolicyRunner::Load(const PolicyWeights& weights) {
  if (absl::Status status = ImportPolicyWeights(weights, *policy_, normalizer_);
      !status.ok()) {
    return status;
  }
  StartEpisode();
  return absl::OkStatus();
}

void PolicyRunner::Seed(uint64_t seed) {
  generator_ = at::detail::createCPUGenerator(seed);
}

void PolicyRunner::StartEpisode() {
  if (policy_->recurrent()) state_ = policy_->trunk()->InitialState(1);
}

std::vector<double> PolicyRunner::Act(absl::Span<const double> observation,
                                      bool deterministic,
                                      absl::Span<const uint8_t> mask) {
  at::NoGradGuard no_grad;
  const at::Tensor x = ObservationsForNetwork(
      spec_, normalizer_, ObservationTensor(spec_, observation.data(), 1),
      observation_clip_);
  at::Tensor output =
      policy_->recurrent() ? policy_->Step(x, state_) : policy_->forward(x);
  if (!mask.empty()) {
    MaskLogitsInPlace(output.data_ptr<float>(), mask.data(), 1,
                      static_cast<int64_t>(mask.size()));
  }
  const at::Tensor action = policy_->Act(output, deterministic, generator_)
                                .to(at::kDouble)
                                .contiguous();
  const double* data = action.data_ptr<double>();
  return std::vector<double>(data, data + action.numel());
}

}  // namespace vantage
