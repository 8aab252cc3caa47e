#include "common/util/phase_times.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_format.h"

namespace vantage {

PhaseTimes::PhaseTimes(std::vector<std::string> phases)
    : phases_(std::move(phases)),
      seconds_(phases_.size(), 0.0),
      start_(std::chrono::steady_clock::now()) {}

std::string PhaseTimes::Summary(const std::string& rest) const {
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_)
          .count();
  const double scale = wall > 0.0 ? 100.0 / wall : 0.0;
  std::string line = absl::StrFormat("time split over %.1f s:", wall);
  double spent = 0.0;
  for (size_t i = 0; i < phases_.size(); ++i) {
    absl::StrAppendFormat(&line, " %s %.1f%%,", phases_[i],
                          seconds_[i] * scale);
    spent += seconds_[i];
  }
  absl::StrAppendFormat(&line, " %s %.1f%%", rest,
                        std::max(0.0, wall - spent) * scale);
  return line;
}

}  // namespace vantage
