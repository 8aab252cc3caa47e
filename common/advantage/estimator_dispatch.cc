#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "common/advantage/estimator_kernels.h"
#include "common/advantage/estimator_kernels_isa.h"

namespace vantage {
namespace {

bool UseAvx2() {
#if defined(VANTAGE_HAVE_AVX2_KERNELS)
  static const bool use = [] {
    const char* forced = std::getenv("VANTAGE_KERNELS");
    if (forced != nullptr && std::strcmp(forced, "baseline") == 0) {
      return false;
    }
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return use;
#else
  return false;
#endif
}

}  // namespace

const char* ActiveKernelIsa() { return UseAvx2() ? "avx2" : "baseline"; }

template <typename Scalar, typename Out>
void RunEstimators(const RolloutView<Scalar>& rollout,
                   const EstimatorSettings& settings,
                   const EstimatorOutputs<Out>& outputs) {
#if defined(VANTAGE_HAVE_AVX2_KERNELS)
  if (UseAvx2()) return isa_avx2::RunEstimators(rollout, settings, outputs);
#endif
  isa_baseline::RunEstimators(rollout, settings, outputs);
}

void KStepFromBasis(const double* longest, const double* remaining,
                    int64_t steps, int64_t streams, int64_t k, double gamma,
                    double* out) {
#if defined(VANTAGE_HAVE_AVX2_KERNELS)
  if (UseAvx2()) {
    return isa_avx2::KStepFromBasis(longest, remaining, steps, streams, k,
                                    gamma, out);
  }
#endif
  isa_baseline::KStepFromBasis(longest, remaining, steps, streams, k, gamma,
                               out);
}

std::vector<std::pair<int, int>> SortingNetwork(int n) {
  std::vector<std::pair<int, int>> pairs;
  if (n < 2) return pairs;
  int top = 1;  // 2^(t-1) with t = ceil(log2 n), Knuth's Algorithm 5.2.2M
  while (2 * top < n) top *= 2;
  for (int p = top; p > 0; p /= 2) {
    int q = top;
    int r = 0;
    int d = p;
    while (true) {
      for (int i = 0; i + d < n; ++i) {
        if ((i & p) == r) pairs.emplace_back(i, i + d);
      }
      if (q == p) break;
      d = q - p;
      q /= 2;
      r = p;
    }
  }
  return pairs;
}

std::vector<std::pair<int, int>> SelectionNetwork(int n, int position) {
  const std::vector<std::pair<int, int>> sorting = SortingNetwork(n);
  // Walking backwards, a pair matters if it writes a wire that matters;
  // then both of its inputs matter.
  std::vector<bool> matters(n, false);
  matters[position] = true;
  std::vector<std::pair<int, int>> kept;
  for (auto it = sorting.rbegin(); it != sorting.rend(); ++it) {
    if (matters[it->first] || matters[it->second]) {
      kept.push_back(*it);
      matters[it->first] = matters[it->second] = true;
    }
  }
  return std::vector<std::pair<int, int>>(kept.rbegin(), kept.rend());
}

template void RunEstimators<float, float>(const RolloutView<float>&,
                                          const EstimatorSettings&,
                                          const EstimatorOutputs<float>&);
template void RunEstimators<double, double>(const RolloutView<double>&,
                                            const EstimatorSettings&,
                                            const EstimatorOutputs<double>&);

}  // namespace vantage
