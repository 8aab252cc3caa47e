#ifndef VANTAGE_LEARNER_INGEST_SEGMENT_INTAKE_H_
#define VANTAGE_LEARNER_INGEST_SEGMENT_INTAKE_H_

// The learner's intake, the first stage of its pipeline: segments in,
// checked (unless their source checked them), stale steps dropped, streams
// stitched into rollouts, complete batches of rollouts out.

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/rollout/segment.h"
#include "common/rollout/segment_queue.h"
#include "learner/ingest/batch_plan.h"
#include "learner/ingest/rollout_stitcher.h"
#include "learner/ingest/segment_check.h"
#include "learner/learner_config.h"

namespace vantage {

class SegmentIntake {
 public:
  // What the intake refused or dropped since its counts were last reset,
  // and the episodes its segments ended.
  struct Counts {
    int64_t rejected = 0;
    int64_t stale_segments = 0;
    int64_t stale_steps = 0;
    int64_t episodes = 0;
  };

  explicit SegmentIntake(const LearnerConfig& config);

  // Receives from `source` until the rollouts complete and recent enough
  // to train the policy at `version` make a batch: `rollouts_per_batch` of
  // them, or as many as the plan says (SetPlan); returns them, oldest
  // first, and keeps the rest for later batches. Steps too stale for
  // `version` are dropped first, whether buffered or arriving. Returns the
  // source's error once it fails (closed).
  absl::StatusOr<std::vector<Rollout>> NextBatch(SegmentSource& source,
                                                 int64_t version);
  // Null: the fixed batch. The plan must outlive the intake's use of it.
  void SetPlan(BatchPlan* plan) { plan_ = plan; }

  // Frees the stitching state of an actor that is gone (its registration
  // expired); rollouts it already completed still train.
  void ForgetActor(int64_t actor_id) { stitcher_.ForgetActor(actor_id); }
  const RolloutStitcher& stitcher() const { return stitcher_; }
  // Steps held for later batches: partial rollouts and complete ones that
  // wait for their batch.
  int64_t buffered_steps() const {
    return stitcher_.buffered_steps() +
           static_cast<int64_t>(pending_.size()) * horizon_;
  }

  // Returns of the episodes reported by accepted segments, newest last (at
  // most 100 kept); a resumed learner restores them.
  const std::deque<double>& recent_returns() const { return recent_returns_; }
  void RestoreRecentReturns(std::deque<double> returns) {
    recent_returns_ = std::move(returns);
  }

  const Counts& unreported() const { return unreported_; }
  // The counts start again from 0 (an update reported them).
  void ResetCounts() { unreported_ = Counts(); }
  // The first refusal's reason since the last call, naming the actor and
  // slot ("" if none).
  std::string TakeFirstRejection();

 private:
  // Drops what became too stale for `version` among the complete rollouts
  // and the partial ones.
  void DropStale(int64_t version);
  // How many of the complete rollouts make the batch now (0: not yet).
  int64_t BatchSize(int64_t version) const;
  // Checks, stitches and counts one segment.
  void Accept(Segment segment, bool checked, int64_t version);
  void Reject(int64_t actor_id, int64_t env_slot, const absl::Status& why);

  const SegmentCheck check_;
  const int64_t horizon_;
  const int64_t rollouts_per_batch_;
  const int64_t max_buffered_steps_;
  RolloutStitcher stitcher_;
  BatchPlan* plan_ = nullptr;
  std::vector<Rollout> pending_;
  std::deque<double> recent_returns_;
  Counts unreported_;
  std::string first_rejection_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_INGEST_SEGMENT_INTAKE_H_
