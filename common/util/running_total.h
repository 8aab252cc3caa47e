#ifndef VANTAGE_COMMON_UTIL_RUNNING_TOTAL_H_
#define VANTAGE_COMMON_UTIL_RUNNING_TOTAL_H_

#include <cstdint>

namespace vantage {

// Turns a running total that some component already keeps into the
// increments a monotonic counter (e.g. a Prometheus counter) needs. Callers
// can then report the total whenever they like: the same total twice, or
// an older total arriving late from another thread, adds nothing. Not
// thread-safe: the owner serialises calls.
class RunningTotal {
 public:
  // What `total` adds beyond the highest total seen so far; 0 if it is not
  // above it.
  int64_t Advance(int64_t total) {
    if (total <= seen_) return 0;
    const int64_t increment = total - seen_;
    seen_ = total;
    return increment;
  }

  int64_t seen() const { return seen_; }

 private:
  int64_t seen_ = 0;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_RUNNING_TOTAL_H_
