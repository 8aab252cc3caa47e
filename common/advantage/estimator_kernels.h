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
  const bool* terminated = nullptr;
  const bool* truncated = nullptr;
  // Read only where truncated is set.
  const Scalar* truncation_values = nullptr;
  const Scalar* last_values = nullptr;  // [streams] V(s_T)
};

// What every estimator needs, one pass over the inputs:
//   delta[t] = r_t + gamma * B_t - V_t with the bootstrap B_t = 0 if the
//     episode terminated at t, V(final observation) if it was truncated at
//     t, V(s_T) at the rollout's last step, V(s_{t+1}) otherwise
//     (terminated wins over truncated);
//   continues[t] = 1 if step t+1 belongs to t's episode inside this rollout,
//     else 0.
template <typename Scalar>
void ComputeTdErrors(const RolloutView<Scalar>& rollout, double gamma,
                     double* delta, double* continues);

// GAE(gamma, lambda), one backward pass.
template <typename Out>
void GaeKernel(int64_t steps, int64_t streams, const double* delta,
               const double* continues, double gamma, double lambda, Out* gae);

// The path ensemble in compact form: longest[t] is the longest estimate
// available at t (to the end of t's episode or of the rollout) and
// remaining[t] its number of steps L_t. Every k-step estimate follows as
//   A^(k)_t = longest[t] - gamma^k * longest[t+k]   if k < L_t,
//   A^(k)_t = longest[t]                            otherwise,
// because the discounted sums telescope inside one episode. remaining is
// stored as double so that it vectorises together with longest.
struct PathEnsembleBasis {
  const double* longest = nullptr;
  const double* remaining = nullptr;
};
void ComputePathEnsembleBasis(int64_t steps, int64_t streams,
                              const double* delta, const double* continues,
                              double gamma, double* longest, double* remaining);

// A^(k) for one k over the whole rollout.
void KStepKernel(const PathEnsembleBasis& basis, int64_t steps, int64_t streams,
                 int64_t k, double gamma, double* out);

// The order statistic over {A^(k) : k in ensemble} at every element, in
// O(steps * streams * |E|) plus a sorting network for order:d. Computes the
// basis into longest/remaining ([steps, streams] each) on the way, in one
// blocked backward pass. `ensemble` must be sorted ascending (maxabs breaks
// ties towards the smaller k); statistic.kind must not be kGae.
template <typename Out>
void EnsembleStatisticKernel(int64_t steps, int64_t streams,
                             const double* delta, const double* continues,
                             double gamma, const std::vector<int64_t>& ensemble,
                             const Statistic& statistic, double* longest,
                             double* remaining, Out* out);

// The compare-exchange pairs (i < j) of a sorting network for n inputs
// (Batcher's merge exchange, valid for any n).
std::vector<std::pair<int, int>> SortingNetwork(int n);

}  // namespace vantage

#endif  // VANTAGE_COMMON_ADVANTAGE_ESTIMATOR_KERNELS_H_
