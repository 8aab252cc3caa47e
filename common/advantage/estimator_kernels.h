#ifndef VANTAGE_COMMON_ADVANTAGE_ESTIMATOR_KERNELS_H_
#define VANTAGE_COMMON_ADVANTAGE_ESTIMATOR_KERNELS_H_

// The advantage estimators on plain row-major [steps, streams] arrays. Kept
// free of LibTorch so the arithmetic compiles fast and vectorises over the
// streams; advantage.h wraps it for tensors. Inputs may be float or double
// (Scalar); every sum is accumulated in double precision. Element (t, s) of
// an array lives at index t * streams + s.

#include <cstdint>
#include <utility>
#include <vector>

#include "common/advantage/advantage_config.h"

namespace vantage {

template <typename Scalar>
struct RolloutView {
  int64_t steps = 0;
  int64_t streams = 0;
  const Scalar* rewards = nullptr;
  const Scalar* values = nullptr;  // V(s_t)
  // Terminated wins where both flags are set.
  const bool* terminated = nullptr;
  const bool* truncated = nullptr;
  // Read only where truncated is set.
  const Scalar* truncation_values = nullptr;
  const Scalar* last_values = nullptr;  // [streams] V(s_T)
};

struct EstimatorSettings {
  double gamma = 0.99;
  double lambda = 0.95;
  // Sorted ascending (maxabs breaks ties towards the smaller k), distinct,
  // positive; non-empty when `biased` is requested.
  std::vector<int64_t> ensemble;
  Statistic statistic;
};

// Every output is optional (null: not computed). All are [steps, streams].
//
// The path ensemble is kept in compact form, the basis: longest[t] is the
// longest estimate available at t (to the end of t's episode or of the
// rollout) and remaining[t] its number of steps L_t, stored as double so it
// vectorises with longest. Every k-step estimate follows from it as
//   A^(k)_t = longest[t] - gamma^k * longest[t+k]   if k < L_t,
//   A^(k)_t = longest[t]                            otherwise,
// because discounted sums telescope inside one episode.
template <typename Out>
struct EstimatorOutputs {
  Out* gae = nullptr;     // GAE(gamma, lambda)
  Out* biased = nullptr;  // settings.statistic over settings.ensemble
  // The basis; required when `biased` is requested.
  double* longest = nullptr;
  double* remaining = nullptr;
};

// One blocked backward pass over the rollout computes the TD errors
//   delta_t = r_t + gamma * B_t - V_t, with B_t = 0 if the episode
//   terminated at t, V(final observation) if it was truncated at t, V(s_T)
//   at the rollout's last step and V(s_{t+1}) otherwise,
// then every requested output. Blocks keep what they compute in cache for
// the members that read it. Cost O(steps * streams * |E|) plus a sorting
// network per element for order:d.
template <typename Scalar, typename Out>
void RunEstimators(const RolloutView<Scalar>& rollout,
                   const EstimatorSettings& settings,
                   const EstimatorOutputs<Out>& outputs);

// A^(k) for one k over the whole rollout from a computed basis.
void KStepFromBasis(const double* longest, const double* remaining,
                    int64_t steps, int64_t streams, int64_t k, double gamma,
                    double* out);

// The compare-exchange pairs (i < j) of a sorting network for n inputs
// (Batcher's merge exchange, valid for any n), applied in order.
std::vector<std::pair<int, int>> SortingNetwork(int n);

// SortingNetwork(n) without the pairs that cannot affect output `position`
// (0-based): afterwards that output holds the value of that rank.
std::vector<std::pair<int, int>> SelectionNetwork(int n, int position);

}  // namespace vantage

#endif  // VANTAGE_COMMON_ADVANTAGE_ESTIMATOR_KERNELS_H_
