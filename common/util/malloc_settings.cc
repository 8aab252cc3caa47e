#include "common/util/malloc_settings.h"

#include <climits>
#include <cstdlib>
#include <cstring>

#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace vantage {

bool EnvironmentSetsMalloc(const char* mmap_max, const char* trim_threshold,
                           const char* tunables) {
  if (mmap_max != nullptr || trim_threshold != nullptr) return true;
  return tunables != nullptr &&
         (std::strstr(tunables, "glibc.malloc.mmap_max") != nullptr ||
          std::strstr(tunables, "glibc.malloc.trim_threshold") != nullptr);
}

MallocSettings KeepFreedMemoryForReuse() {
#ifdef __GLIBC__
  if (EnvironmentSetsMalloc(std::getenv("MALLOC_MMAP_MAX_"),
                            std::getenv("MALLOC_TRIM_THRESHOLD_"),
                            std::getenv("GLIBC_TUNABLES"))) {
    return MallocSettings::kEnvironment;
  }
  // Without mmap a block too large for a thread's arena comes from the main
  // heap (glibc retries there), which grows by brk and keeps what is freed.
  mallopt(M_MMAP_MAX, 0);
  // mallopt takes an int: INT_MAX bytes is the largest threshold it sets.
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
  return MallocSettings::kKeepFreedMemory;
#else
  return MallocSettings::kNotGlibc;
#endif
}

}  // namespace vantage
