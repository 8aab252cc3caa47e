#ifndef VANTAGE_TESTS_FAKES_RANDOM_POLICY_H_
#define VANTAGE_TESTS_FAKES_RANDOM_POLICY_H_

// Random weights for tests that compare a policy's forward pass with
// another implementation of it.

#include <ATen/ATen.h>

#include <cmath>

#include "common/env/environment.h"
#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"
#include "gtest/gtest.h"

namespace vantage {

// Weights of the scale the initialisation gives hidden layers, 1 /
// sqrt(fan-in) per weight (the output layer too, whose initial gain of 0.01
// would leave every output near 0; convolutions by their kernel's fan-in),
// random biases and log-std, and a random normaliser for real-valued
// observations.
inline void RandomisePolicy(PolicyNetworkImpl& policy,
                            RunningMeanStd& normalizer, const EnvSpec& spec) {
  at::NoGradGuard no_grad;
  for (at::Tensor& parameter : policy.parameters()) {
    const double scale =
        parameter.dim() >= 2 ? 1.0 / std::sqrt(parameter[0].numel()) : 0.5;
    parameter.copy_(at::randn(parameter.sizes()) * scale);
  }
  if (!spec.byte_observations()) {
    ASSERT_TRUE(
        normalizer
            .Restore(10.0, at::randn({spec.observation_size}, at::kDouble),
                     at::rand({spec.observation_size}, at::kDouble) + 0.1)
            .ok());
  }
}

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_RANDOM_POLICY_H_
