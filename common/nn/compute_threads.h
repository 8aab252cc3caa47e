#ifndef VANTAGE_COMMON_NN_COMPUTE_THREADS_H_
#define VANTAGE_COMMON_NN_COMPUTE_THREADS_H_

// LibTorch's intra-op thread count, for the commands that set it before
// they run anything (actors compute on one thread: several share a core).
// A header without LibTorch, so that the commands compile without it.

namespace vantage {

void SetComputeThreads(int threads);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_COMPUTE_THREADS_H_
