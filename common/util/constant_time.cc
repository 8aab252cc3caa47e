#include "common/util/constant_time.h"

namespace vantage {

bool ConstantTimeEquals(absl::string_view a, absl::string_view b) {
  // Every byte of `a` is compared whatever `b`'s length, so neither a
  // length mismatch nor the first differing byte ends the loop early.
  unsigned char difference = a.size() == b.size() ? 0 : 1;
  for (size_t i = 0; i < a.size(); ++i) {
    const unsigned char other =
        i < b.size() ? static_cast<unsigned char>(b[i]) : 0;
    difference |= static_cast<unsigned char>(a[i]) ^ other;
  }
  return difference == 0;
}

}  // namespace vantage
