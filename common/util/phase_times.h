#ifndef VANTAGE_COMMON_UTIL_PHASE_TIMES_H_
#define VANTAGE_COMMON_UTIL_PHASE_TIMES_H_

// Where a process's wall time went: seconds added to named phases of its
// loop, and the rest of the time since construction counted as waiting.
// Actors and the learner print it as one line when they stop
// ("time split over 41.2 s: inference 31.0%, physics 20.1%, ..."), which
// `vantage bench train` reads from the run's log.

#include <chrono>
#include <string>
#include <vector>

namespace vantage {

class PhaseTimes {
 public:
  // `phases`: the names, in the order Add takes their indices.
  explicit PhaseTimes(std::vector<std::string> phases);

  void Add(size_t phase, double seconds) { seconds_[phase] += seconds; }

  // "time split over W s: a X%, b Y%, <rest> Z%", every share of the wall
  // time since construction.
  std::string Summary(const std::string& rest) const;

 private:
  std::vector<std::string> phases_;
  std::vector<double> seconds_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_PHASE_TIMES_H_
