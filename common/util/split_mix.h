#ifndef VANTAGE_COMMON_UTIL_SPLIT_MIX_H_
#define VANTAGE_COMMON_UTIL_SPLIT_MIX_H_

#include <cstdint>

namespace vantage {

// A seed for member `index` of a family seeded `base`: SplitMix64's output
// for state base + (index + 1) * its odd increment. Each step is a
// bijection of 64-bit words, so distinct indices never share a seed, and
// the seeds scatter far from base + i.
inline uint64_t SplitMixSeed(uint64_t base, uint64_t index) {
  uint64_t z = base + 0x9E3779B97F4A7C15ULL * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_SPLIT_MIX_H_
