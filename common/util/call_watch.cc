#include "common/util/call_watch.h"

#include <cstdint>
#include <map>
#include <mutex>

namespace vantage {
namespace {

struct Call {
  const std::string* subject;
  const char* call;
  absl::Time began;
};

// Few calls are ever in progress at once (one per env thread).
struct Calls {
  std::mutex mutex;
  std::map<int64_t, Call> running;
  int64_t next_id = 0;
};

Calls& TheCalls() {
  static Calls* calls = new Calls();
  return *calls;
}

}  // namespace

WatchedCall::WatchedCall(const std::string& subject, const char* call) {
  const absl::Time now = absl::Now();
  Calls& calls = TheCalls();
  std::lock_guard<std::mutex> lock(calls.mutex);
  id_ = calls.next_id++;
  calls.running.emplace_hint(calls.running.end(), id_,
                             Call{&subject, call, now});
}

WatchedCall::~WatchedCall() {
  Calls& calls = TheCalls();
  std::lock_guard<std::mutex> lock(calls.mutex);
  calls.running.erase(id_);
}

LongestCall LongestWatchedCall(absl::Time now) {
  Calls& calls = TheCalls();
  std::lock_guard<std::mutex> lock(calls.mutex);
  if (calls.running.empty()) return {};
  // Ids grow with time: the first entry began first.
  const Call& first = calls.running.begin()->second;
  return {*first.subject + ": " + first.call, now - first.began};
}

}  // namespace vantage
