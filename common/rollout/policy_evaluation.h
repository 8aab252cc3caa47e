#ifndef VANTAGE_COMMON_ROLLOUT_POLICY_EVALUATION_H_
#define VANTAGE_COMMON_ROLLOUT_POLICY_EVALUATION_H_

// What an evaluation of a policy version found: the returns and lengths of
// its episodes, as the actor side produces them and the learner records
// them (progress.csv, Prometheus, the best checkpoint).

#include <cstdint>
#include <vector>

namespace vantage {

struct PolicyEvaluation {
  int64_t version = 0;
  std::vector<double> returns;
  std::vector<int64_t> lengths;
};

// The spread of an evaluation's returns (all NaN without episodes).
struct EvaluationSummary {
  int64_t version = 0;
  double mean = 0.0;
  double std = 0.0;  // population standard deviation over its episodes
  double min = 0.0;
  double max = 0.0;
  double mean_length = 0.0;
};

EvaluationSummary Summarize(const PolicyEvaluation& evaluation);

}  // namespace vantage

#endif  // VANTAGE_COMMON_ROLLOUT_POLICY_EVALUATION_H_
