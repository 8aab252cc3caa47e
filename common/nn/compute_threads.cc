#include "common/nn/compute_threads.h"

#include <ATen/Parallel.h>
#include <dlfcn.h>

namespace vantage {

void SetComputeThreads(int threads) {
  at::set_num_threads(threads);
  // Looked up rather than linked: libblas.so.3 may be another BLAS.
  // deploy/setup.sh installs OpenBLAS's pthread build, the one that may be
  // called from several threads at once; its GEMMs stay in the calling
  // thread so that they do not compete with the process's own threads and
  // the other processes' for the cores.
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(
          dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) {
    set(1);
  }
}

}  // namespace vantage
