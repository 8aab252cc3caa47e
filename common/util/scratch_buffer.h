#ifndef VANTAGE_COMMON_UTIL_SCRATCH_BUFFER_H_
#define VANTAGE_COMMON_UTIL_SCRATCH_BUFFER_H_

// The hand-written kernels (the actors' MLP policy, the learner's flat
// update) keep their scratch arrays between calls and only ever grow them,
// so that a steady loop allocates nothing.

#include <cstdint>
#include <vector>

namespace vantage {

// `buffer` grown to at least `size` elements (never shrunk), and its data.
template <typename T>
T* GrowScratch(std::vector<T>& buffer, int64_t size) {
  if (static_cast<int64_t>(buffer.size()) < size) buffer.resize(size);
  return buffer.data();
}

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_SCRATCH_BUFFER_H_
