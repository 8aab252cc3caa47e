#ifndef VANTAGE_COMMON_ADVANTAGE_ADVANTAGE_CONFIG_H_
#define VANTAGE_COMMON_ADVANTAGE_ADVANTAGE_CONFIG_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace vantage {

// The order statistic applied over the path ensemble at each step.
enum class StatisticKind {
  kGae,     // no bias: the biased estimate is GAE itself
  kMax,     // optimistic
  kMin,     // risk-averse
  kMaxAbs,  // the member of largest |A|, ties to the smaller k
  kOrder,   // the d-th smallest member (1-based, duplicates counted)
};

struct Statistic {
  StatisticKind kind = StatisticKind::kGae;
  int order = 0;  // d of `order:d`; 0 for every other kind
};

// Parses "gae", "max", "min", "maxabs" or "order:D"; the error lists the
// valid names.
absl::StatusOr<Statistic> ParseStatistic(absl::string_view name);
std::string StatisticName(const Statistic& statistic);

// The defaults are a training run's: the paper's maxabs over {1, 16, 64,
// 2048} with rho 0.4 (lambda's default is the algorithm's, see
// learner/algorithms/run_defaults.h).
struct AdvantageConfig {
  double gamma = 0.99;
  double lambda = 0.95;
  // The ensemble index set E; any order, no duplicates.
  std::vector<int64_t> ensemble = {1, 16, 64, 2048};
  Statistic statistic = {StatisticKind::kMaxAbs, 0};
  // Probability that a sample's policy advantage is the biased one.
  double rho = 0.4;

  // gamma in (0,1], lambda in [0,1], rho in [0,1], E non-empty with
  // distinct positive members, and for order:d, d in 1..|E|.
  absl::Status Validate() const;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ADVANTAGE_ADVANTAGE_CONFIG_H_
