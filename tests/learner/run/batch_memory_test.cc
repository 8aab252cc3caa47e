#include "learner/run/batch_memory.h"

#include <cstdlib>

#include "gtest/gtest.h"

namespace vantage {
namespace {

LearnerConfig ConfigOf(int64_t observation_size, int64_t horizon,
                       int64_t streams) {
  LearnerConfig config;
  config.spec.observation_size = observation_size;
  config.horizon = horizon;
  config.rollouts_per_batch = streams;
  return config;
}

// A first-person maze batch (8 x 500 frames of 3 x 42 x 42) is above
// glibc's largest mmap threshold, 32 MiB; Hopper's 2048 steps are far
// below it, and keep glibc's defaults.
TEST(BatchMemoryTest, OnlyBatchesAboveTheMmapThresholdKeepFreedMemory) {
  EXPECT_EQ(BatchObservationBytes(ConfigOf(3 * 42 * 42, 500, 8)), 84672000);
  EXPECT_EQ(BatchObservationBytes(ConfigOf(11, 2048, 1)), 90112);
  EXPECT_FALSE(KeepFreedMemoryForLargeBatches(ConfigOf(11, 2048, 1)));
  // 32 KiB short of 32 MiB.
  EXPECT_EQ(BatchObservationBytes(ConfigOf(1023, 2048, 4)),
            (int64_t{32} << 20) - 32768);
  EXPECT_FALSE(KeepFreedMemoryForLargeBatches(ConfigOf(1023, 2048, 4)));
  EXPECT_EXIT(
      {
        unsetenv("MALLOC_MMAP_MAX_");
        unsetenv("MALLOC_TRIM_THRESHOLD_");
        unsetenv("GLIBC_TUNABLES");
        std::exit(KeepFreedMemoryForLargeBatches(ConfigOf(3 * 42 * 42, 500, 8))
                      ? 0
                      : 1);
      },
      testing::ExitedWithCode(0),
      "learner: a batch's observations take 85 MB, so freed memory is kept "
      "for reuse \\(MALLOC_MMAP_MAX_=65536 keeps glibc's defaults\\)");
  EXPECT_EXIT(
      {
        setenv("MALLOC_MMAP_MAX_", "65536", 1);
        std::exit(KeepFreedMemoryForLargeBatches(ConfigOf(3 * 42 * 42, 500, 8))
                      ? 0
                      : 1);
      },
      testing::ExitedWithCode(0),
      "take 85 MB, but glibc's malloc settings come from the environment");
}

}  // namespace
}  // namespace vantage
