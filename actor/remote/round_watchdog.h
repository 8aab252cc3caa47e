#ifndef VANTAGE_ACTOR_REMOTE_ROUND_WATCHDOG_H_
#define VANTAGE_ACTOR_REMOTE_ROUND_WATCHDOG_H_

// Ends the actor process when one environment round runs longer than the
// run's actor stall timeout. A hung environment (a Python step() that
// never returns, a simulator in an endless loop) cannot be interrupted
// from outside its thread, so a new process is how the actor comes back:
// its launcher restarts it (`vantage train`), as a Deployment restarts its
// pod. The message names the environment call that never returned.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "absl/time/time.h"

namespace vantage {

// The exit code of an actor whose round stalled (EX_SOFTWARE is 70; 75,
// EX_TEMPFAIL, says "try again": a restart may well go on).
inline constexpr int kStalledActorExitCode = 75;

class RoundWatchdog {
 public:
  // `name`: the actor's, for the message; `env`: its environment.
  RoundWatchdog(std::string name, std::string env);
  ~RoundWatchdog();
  RoundWatchdog(const RoundWatchdog&) = delete;
  RoundWatchdog& operator=(const RoundWatchdog&) = delete;

  // Rounds longer than `timeout` end the process; zero or less: never.
  void SetTimeout(absl::Duration timeout);
  // Bracket environment work (a round of every environment, less the time
  // its segments wait to be sent: a learner busy updating is no stall).
  void Busy();
  void Idle();

 private:
  void Watch();
  [[noreturn]] void Stalled(absl::Duration running);

  const std::string name_;
  const std::string env_;
  std::atomic<int64_t> timeout_ns_{0};
  // absl::ToUnixNanos of when the work going on began; 0 when idle.
  std::atomic<int64_t> busy_since_ns_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_REMOTE_ROUND_WATCHDOG_H_
