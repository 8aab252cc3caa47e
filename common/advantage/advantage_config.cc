#include "common/advantage/advantage_config.h"

#include <cmath>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"

namespace vantage {
namespace {

constexpr absl::string_view kValidStatistics =
    "gae, max, min, maxabs, order:D (D a 1-based rank)";

}  // namespace

absl::StatusOr<Statistic> ParseStatistic(absl::string_view name) {
  if (name == "gae") return Statistic{StatisticKind::kGae, 0};
  if (name == "max") return Statistic{StatisticKind::kMax, 0};
  if (name == "min") return Statistic{StatisticKind::kMin, 0};
  if (name == "maxabs") return Statistic{StatisticKind::kMaxAbs, 0};
  absl::string_view rank = name;
  if (absl::ConsumePrefix(&rank, "order:")) {
    int order = 0;
    if (!absl::SimpleAtoi(rank, &order) || order < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("statistic '", name,
                       "': the rank after 'order:' must be an integer >= 1"));
    }
    return Statistic{StatisticKind::kOrder, order};
  }
  return absl::InvalidArgumentError(absl::StrCat(
      "unknown statistic '", name, "'; valid statistics: ", kValidStatistics));
}

std::string StatisticName(const Statistic& statistic) {
  switch (statistic.kind) {
    case StatisticKind::kGae:
      return "gae";
    case StatisticKind::kMax:
      return "max";
    case StatisticKind::kMin:
      return "min";
    case StatisticKind::kMaxAbs:
      return "maxabs";
    case StatisticKind::kOrder:
      return absl::StrCat("order:", statistic.order);
  }
  return "unknown";
}

absl::Status AdvantageConfig::Validate() const {
  // Written as !(in range) so that NaN fails every check.
  if (!(gamma > 0.0 && gamma <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("gamma must be in (0, 1], got ", gamma));
  }
  if (!(lambda >= 0.0 && lambda <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("lambda must be in [0, 1], got ", lambda));
  }
  if (!(rho >= 0.0 && rho <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("rho must be in [0, 1], got ", rho));
  }
  if (ensemble.empty()) {
    return absl::InvalidArgumentError(
        "ensemble must list at least one step count k, e.g. 1,16,64,2048");
  }
  absl::flat_hash_set<int64_t> seen;
  for (int64_t k : ensemble) {
    if (k < 1) {
      return absl::InvalidArgumentError(absl::StrCat(
          "ensemble members must be positive step counts, got ", k));
    }
    if (!seen.insert(k).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("ensemble lists k=", k, " more than once"));
    }
  }
  if (statistic.kind == StatisticKind::kOrder &&
      (statistic.order < 1 ||
       statistic.order > static_cast<int64_t>(ensemble.size()))) {
    return absl::InvalidArgumentError(absl::StrCat(
        "statistic order:", statistic.order, " needs a rank in 1..",
        ensemble.size(), " (the ensemble size)"));
  }
  return absl::OkStatus();
}

}  // namespace vantage
