#ifndef VANTAGE_LEARNER_RUN_BACKGROUND_EVALUATOR_H_
#define VANTAGE_LEARNER_RUN_BACKGROUND_EVALUATOR_H_

// Evaluations beside a learner that must not wait for them: on a thread of
// their own at the lowest CPU priority, so they take the machine's spare
// time rather than the learner's. The newest version submitted waits while
// one is evaluated; an older one still waiting is dropped (said once, and
// counted), so a slow evaluation never builds a backlog.

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "common/nn/policy_weights.h"
#include "common/rollout/policy_evaluation.h"
#include "learner/run/evaluate_policy.h"

namespace vantage {

class BackgroundEvaluator {
 public:
  explicit BackgroundEvaluator(EvaluatePolicy evaluate);
  // Waits for the evaluation in progress, if any.
  ~BackgroundEvaluator();
  BackgroundEvaluator(const BackgroundEvaluator&) = delete;
  BackgroundEvaluator& operator=(const BackgroundEvaluator&) = delete;

  void Submit(PolicyWeights weights);
  // The evaluations finished since the last call, oldest first (a failed
  // one is said on stderr and not returned).
  std::vector<PolicyEvaluation> TakeFinished();
  // Waits until every submitted version is evaluated (a run's end: its
  // last row holds the final version's evaluation).
  void Drain();
  // Versions dropped unevaluated because a newer one came first.
  int64_t skipped() const;

 private:
  void Loop();

  const EvaluatePolicy evaluate_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<PolicyWeights> waiting_;
  std::vector<PolicyEvaluation> finished_;
  int64_t skipped_ = 0;
  bool busy_ = false;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_BACKGROUND_EVALUATOR_H_
