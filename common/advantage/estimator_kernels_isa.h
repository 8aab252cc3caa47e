#ifndef VANTAGE_COMMON_ADVANTAGE_ESTIMATOR_KERNELS_ISA_H_
#define VANTAGE_COMMON_ADVANTAGE_ESTIMATOR_KERNELS_ISA_H_

// The per-instruction-set copies of the estimator kernels behind
// estimator_kernels.h. Only estimator_dispatch.cc and tests use this.

#include "common/advantage/estimator_kernels.h"

#define VANTAGE_DECLARE_ESTIMATOR_KERNELS(isa)                                 \
  namespace isa {                                                              \
  template <typename Scalar, typename Out>                                     \
  void RunEstimators(const RolloutView<Scalar>& rollout,                       \
                     const EstimatorSettings& settings,                        \
                     const EstimatorOutputs<Out>& outputs);                    \
  void KStepFromBasis(const double* longest, const double* remaining,          \
                      int64_t steps, int64_t streams, int64_t k, double gamma, \
                      double* out);                                            \
  }

namespace vantage {

// Plain x86-64 (SSE2) or whatever the compiler targets by default.
VANTAGE_DECLARE_ESTIMATOR_KERNELS(isa_baseline)
#if defined(VANTAGE_HAVE_AVX2_KERNELS)
VANTAGE_DECLARE_ESTIMATOR_KERNELS(isa_avx2)
#endif

// The copy that estimator_kernels.h's functions run: AVX2 where the build
// has it and the CPU supports it, unless VANTAGE_KERNELS=baseline is set in
// the environment.
const char* ActiveKernelIsa();

}  // namespace vantage

#undef VANTAGE_DECLARE_ESTIMATOR_KERNELS

#endif  // VANTAGE_COMMON_ADVANTAGE_ESTIMATOR_KERNELS_ISA_H_
