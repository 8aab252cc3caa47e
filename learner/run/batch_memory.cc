#include "learner/run/batch_memory.h"

#include <cstdio>

#include "common/util/malloc_settings.h"

namespace vantage {

int64_t BatchObservationBytes(const LearnerConfig& config) {
  return config.horizon * config.rollouts_per_batch *
         config.spec.observation_size * static_cast<int64_t>(sizeof(float));
}

bool KeepFreedMemoryForLargeBatches(const LearnerConfig& config) {
  const int64_t bytes = BatchObservationBytes(config);
  if (bytes < kLargestMmapThreshold) return false;
  const MallocSettings settings = KeepFreedMemoryForReuse();
  std::fprintf(
      stderr, "learner: a batch's observations take %.0f MB, %s\n",
      static_cast<double>(bytes) / 1e6,
      settings == MallocSettings::kKeepFreedMemory
          ? "so freed memory is kept for reuse (MALLOC_MMAP_MAX_=65536 "
            "keeps glibc's defaults)"
      : settings == MallocSettings::kEnvironment
          ? "but glibc's malloc settings come from the environment"
          : "but the C library is not glibc: its own settings hold");
  return true;
}

}  // namespace vantage
