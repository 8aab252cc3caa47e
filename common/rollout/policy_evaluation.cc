#include "common/rollout/policy_evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace vantage {

EvaluationSummary Summarize(const PolicyEvaluation& evaluation) {
  EvaluationSummary summary;
  summary.version = evaluation.version;
  const std::vector<double>& r = evaluation.returns;
  if (r.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    summary.mean = summary.std = summary.min = summary.max = nan;
    summary.mean_length = nan;
    return summary;
  }
  const double n = static_cast<double>(r.size());
  summary.mean = std::accumulate(r.begin(), r.end(), 0.0) / n;
  double squares = 0.0;
  for (double value : r)
    squares += (value - summary.mean) * (value - summary.mean);
  summary.std = std::sqrt(squares / n);
  summary.min = *std::min_element(r.begin(), r.end());
  summary.max = *std::max_element(r.begin(), r.end());
  const std::vector<int64_t>& lengths = evaluation.lengths;
  summary.mean_length =
      lengths.empty() ? std::numeric_limits<double>::quiet_NaN()
                      : std::accumulate(lengths.begin(), lengths.end(), 0.0) /
                            static_cast<double>(lengths.size());
  return summary;
}

}  // namespace vantage
