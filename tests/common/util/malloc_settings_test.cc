#include "common/util/malloc_settings.h"

#include <sys/resource.h>

#include <cstdlib>
#include <cstring>

#include "gtest/gtest.h"

namespace vantage {
namespace {

TEST(MallocSettingsTest, GlibcsOwnVariablesDecide) {
  EXPECT_FALSE(EnvironmentSetsMalloc(nullptr, nullptr, nullptr));
  EXPECT_FALSE(EnvironmentSetsMalloc(nullptr, nullptr, "glibc.cpu.x86_ibt=0"));
  EXPECT_TRUE(EnvironmentSetsMalloc("65536", nullptr, nullptr));
  EXPECT_TRUE(EnvironmentSetsMalloc(nullptr, "131072", nullptr));
  EXPECT_TRUE(EnvironmentSetsMalloc(
      nullptr, nullptr, "glibc.cpu.x86_ibt=0:glibc.malloc.mmap_max=0"));
  EXPECT_TRUE(EnvironmentSetsMalloc(nullptr, nullptr,
                                    "glibc.malloc.trim_threshold=1000000"));
}

constexpr size_t kBatchBytes = size_t{100} << 20;

// Fills `bytes` at `block` as a batch is filled; the barrier tells the
// compiler the memory is read, so it keeps the stores before a free.
void Fill(void* block, int value) {
  std::memset(block, value, kBatchBytes);
  asm volatile("" : : "r"(block) : "memory");
}

long MinorFaults() {
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// The page faults of allocating and filling a 100 MB batch after an equal
// one was freed: what every update of a run on frames does.
long FaultsOfASecondBatch() {
  void* first = std::malloc(kBatchBytes);
  Fill(first, 1);
  std::free(first);
  const long before = MinorFaults();
  void* second = std::malloc(kBatchBytes);
  Fill(second, 2);
  const long faults = MinorFaults() - before;
  std::free(second);
  return faults;
}

// Each case in a child process of its own: glibc's settings are global.
// With freed memory kept, the second batch reuses the first's pages; with
// glibc's defaults the kernel maps and zeroes all 25,600 of them again.
TEST(MallocSettingsTest, ASecondBatchReusesTheFirstsPages) {
#ifndef __GLIBC__
  GTEST_SKIP() << "glibc only";
#endif
  EXPECT_EXIT(
      {
        unsetenv("MALLOC_MMAP_MAX_");
        unsetenv("MALLOC_TRIM_THRESHOLD_");
        unsetenv("GLIBC_TUNABLES");
        if (KeepFreedMemoryForReuse() != MallocSettings::kKeepFreedMemory) {
          std::exit(3);
        }
        std::exit(FaultsOfASecondBatch() < 1000 ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
  EXPECT_EXIT(
      {
        setenv("MALLOC_MMAP_MAX_", "65536", 1);
        if (KeepFreedMemoryForReuse() != MallocSettings::kEnvironment) {
          std::exit(3);
        }
        std::exit(FaultsOfASecondBatch() > 20000 ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace vantage
