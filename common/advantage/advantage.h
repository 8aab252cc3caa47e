#ifndef VANTAGE_COMMON_ADVANTAGE_ADVANTAGE_H_
#define VANTAGE_COMMON_ADVANTAGE_ADVANTAGE_H_

// Advantage estimation on LibTorch tensors shaped [T, num_streams]: GAE, the
// k-step path ensemble, its biased order statistics and the rho mixing of
// DESIGN.md section 3. Sums are accumulated in double precision; results
// have the dtype of `rewards`.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <random>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/advantage/advantage_config.h"

namespace vantage {

struct AdvantageInputs {
  at::Tensor rewards;     // [T, N] float32/float64
  at::Tensor values;      // [T, N] V(s_t) from the learner's critic
  at::Tensor terminated;  // [T, N] bool: s_{t+1} is terminal, bootstrap 0
  at::Tensor truncated;   // [T, N] bool: a time limit ended the episode at t
  // [T, N] V(final observation) where truncated; other entries are ignored.
  at::Tensor truncation_values;
  at::Tensor last_values;  // [N] V(s_T) after the rollout's last step
};

struct Advantages {
  at::Tensor gae;      // the normal estimate
  at::Tensor biased;   // the statistic over the path ensemble
  at::Tensor mixed;    // mask ? biased : gae, what the policy loss uses
  at::Tensor mask;     // bool, Bernoulli(rho) per sample; none with gae
  at::Tensor returns;  // values + gae, what the critic regresses on
};

// Shapes and dtypes (which every Compute* call checks too) plus finite
// rewards, values, last values and truncation values at truncated steps.
// The finiteness scan is O(T*N), so hot paths that validated their data on
// arrival call the Compute* functions directly.
absl::Status ValidateAdvantageInputs(const AdvantageInputs& inputs);

absl::StatusOr<at::Tensor> ComputeGae(const AdvantageInputs& inputs,
                                      double gamma, double lambda);

// Every A^(k), stacked as [|ks|, T, N] in the order of `ks`.
absl::StatusOr<at::Tensor> ComputeKStepEstimates(
    const AdvantageInputs& inputs, double gamma,
    const std::vector<int64_t>& ks);

// The configured statistic over the path ensemble; GAE for `gae`.
absl::StatusOr<at::Tensor> ComputeBiasedAdvantage(
    const AdvantageInputs& inputs, const AdvantageConfig& config);

// Bool tensor of `shape`, each entry true with probability rho, in
// row-major order from `rng` (two entries per 64-bit draw). rho = 0 gives
// all false and rho = 1 all true, and neither draws from `rng`.
at::Tensor DrawBiasMask(at::IntArrayRef shape, double rho,
                        std::mt19937_64& rng);

// Everything a policy/critic update needs, the mask drawn from `rng`.
absl::StatusOr<Advantages> ComputeAdvantages(const AdvantageInputs& inputs,
                                             const AdvantageConfig& config,
                                             std::mt19937_64& rng);

}  // namespace vantage

#endif  // VANTAGE_COMMON_ADVANTAGE_ADVANTAGE_H_
