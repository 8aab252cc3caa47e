#ifndef VANTAGE_COMMON_UTIL_CALL_WATCH_H_
#define VANTAGE_COMMON_UTIL_CALL_WATCH_H_

// The calls into code vantage does not control (a Python environment's
// step(), reset() ...) that are running now, so that a watchdog that finds
// a process stuck can say which call of which environment never returned.

#include <cstdint>
#include <string>

#include "absl/time/clock.h"
#include "absl/time/time.h"

namespace vantage {

// While alive, `call` ("step()") of `subject` ("python:maze:make") is a call
// in progress. Both must outlive it; nothing is copied or joined (stepping
// builds no strings) until a watchdog asks.
class WatchedCall {
 public:
  WatchedCall(const std::string& subject, const char* call);
  ~WatchedCall();
  WatchedCall(const WatchedCall&) = delete;
  WatchedCall& operator=(const WatchedCall&) = delete;

 private:
  int64_t id_;
};

// The call in progress that began first ("python:maze:make: step()") and
// how long it has run; empty when none is.
struct LongestCall {
  std::string what;
  absl::Duration running;
};
LongestCall LongestWatchedCall(absl::Time now = absl::Now());

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_CALL_WATCH_H_
