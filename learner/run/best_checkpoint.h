#ifndef VANTAGE_LEARNER_RUN_BEST_CHECKPOINT_H_
#define VANTAGE_LEARNER_RUN_BEST_CHECKPOINT_H_

// The best-evaluated checkpoint of a run, kept apart from the newest ones:
// checkpoints/best.pt is the run's checkpoint of the version whose
// evaluation had the highest mean return so far, and checkpoints/best.json
// says which ({"version": V, "eval_return": R, ...}). An evaluation comes
// after its version's checkpoint (in a distributed run, updates later), so
// that checkpoint is held meanwhile as evaluating-<version>.pt, a hard link
// (a copy where the file system has none) that pruning the newest
// checkpoints does not touch.

#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/rollout/policy_evaluation.h"

namespace vantage {

class BestCheckpoint {
 public:
  // The best so far from best.json, if any; checkpoints held for
  // evaluations that never came (the run stopped before) are removed.
  static absl::StatusOr<BestCheckpoint> Open(const std::string& directory);

  std::string best_path() const;
  std::string held_path(int64_t version) const;
  // NaN before any evaluation.
  double best_return() const { return best_return_; }

  // Holds the checkpoint just written of `version` for its evaluation.
  absl::Status Hold(const std::string& checkpoint_path, int64_t version);
  // The evaluation of a held version: its checkpoint becomes best.pt if
  // its mean return beats the best so far (true), and is dropped
  // otherwise. NotFound if the version was not held (nothing changes).
  absl::StatusOr<bool> Offer(const EvaluationSummary& evaluation);

 private:
  explicit BestCheckpoint(std::string directory)
      : directory_(std::move(directory)) {}
  // Removes the held checkpoints of versions before `version`.
  void ReleaseBefore(int64_t version);

  std::string directory_;
  double best_return_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_BEST_CHECKPOINT_H_
