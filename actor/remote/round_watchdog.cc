#include "actor/remote/round_watchdog.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "absl/time/clock.h"
#include "common/util/call_watch.h"

namespace vantage {

RoundWatchdog::RoundWatchdog(std::string name, std::string env)
    : name_(std::move(name)), env_(std::move(env)) {
  thread_ = std::thread([this] { Watch(); });
}

RoundWatchdog::~RoundWatchdog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void RoundWatchdog::SetTimeout(absl::Duration timeout) {
  timeout_ns_ =
      timeout <= absl::ZeroDuration() ? 0 : absl::ToInt64Nanoseconds(timeout);
}

void RoundWatchdog::Busy() { busy_since_ns_ = absl::ToUnixNanos(absl::Now()); }

void RoundWatchdog::Idle() { busy_since_ns_ = 0; }

void RoundWatchdog::Watch() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!wake_.wait_for(lock, std::chrono::milliseconds(250),
                         [this] { return done_; })) {
    const int64_t timeout = timeout_ns_;
    const int64_t began = busy_since_ns_;
    if (timeout == 0 || began == 0) continue;
    const absl::Duration running = absl::Now() - absl::FromUnixNanos(began);
    if (running > absl::Nanoseconds(timeout)) Stalled(running);
  }
}

void RoundWatchdog::Stalled(absl::Duration running) {
  const LongestCall call = LongestWatchedCall();
  const std::string what =
      call.what.empty()
          ? "an environment round of " + env_ + " has run for " +
                absl::FormatDuration(absl::Trunc(running, absl::Seconds(1)))
          : call.what + " has not returned after " +
                absl::FormatDuration(
                    absl::Trunc(call.running, absl::Seconds(1)));
  std::fprintf(
      stderr,
      "%s: %s, beyond the run's actor stall timeout (%s); exiting "
      "(code %d) so that a new process replaces this one\n",
      name_.c_str(), what.c_str(),
      absl::FormatDuration(absl::Nanoseconds(timeout_ns_.load())).c_str(),
      kStalledActorExitCode);
  std::fflush(stderr);
  // The stuck thread holds locks (the GIL, the env's); nothing may wait
  // for them on the way out.
  _exit(kStalledActorExitCode);
}

}  // namespace vantage
