#ifndef VANTAGE_LEARNER_RUN_BATCH_MEMORY_H_
#define VANTAGE_LEARNER_RUN_BATCH_MEMORY_H_

#include <cstdint>

#include "learner/learner_config.h"

namespace vantage {

// The bytes of one batch's observations as the networks take them
// (floats), for this learner's share of the batch.
int64_t BatchObservationBytes(const LearnerConfig& config);

// glibc's largest mmap threshold: blocks above it are always mapped afresh.
inline constexpr int64_t kLargestMmapThreshold = int64_t{32} << 20;

// glibc maps every block above kLargestMmapThreshold afresh and unmaps it
// when freed. When a batch's observations are that large
// (frames: 4000 x 3 x 42 x 42 floats are 85 MB), so are the activations
// over them, and every update would pay the kernel for zeroing new pages;
// the process then keeps freed memory for reuse (KeepFreedMemoryForReuse)
// and says so on stderr. Smaller batches leave glibc's defaults alone.
// Returns whether the batches are that large.
bool KeepFreedMemoryForLargeBatches(const LearnerConfig& config);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_BATCH_MEMORY_H_
