#ifndef VANTAGE_COMMON_UTIL_CONSTANT_TIME_H_
#define VANTAGE_COMMON_UTIL_CONSTANT_TIME_H_

#include "absl/strings/string_view.h"

namespace vantage {

// Equality of secrets whose time depends only on the lengths, never on
// where the contents differ.
bool ConstantTimeEquals(absl::string_view a, absl::string_view b);

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_CONSTANT_TIME_H_
