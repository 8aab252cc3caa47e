#ifndef VANTAGE_COMMON_NN_COMPUTE_THREADS_H_
#define VANTAGE_COMMON_NN_COMPUTE_THREADS_H_

// How many threads a process computes on, for the commands that set it
// before they run anything (actors compute on one thread: several share a
// core): LibTorch's intra-op threads. OpenBLAS, when libblas.so.3 is
// OpenBLAS's pthread build, is kept to the calling thread, as its serial
// build computes (docs/benchmarks.md). A header without LibTorch, so that
// the commands compile without it.

namespace vantage {

void SetComputeThreads(int threads);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_COMPUTE_THREADS_H_
