#ifndef VANTAGE_LEARNER_INGEST_SEGMENT_CHECK_H_
#define VANTAGE_LEARNER_INGEST_SEGMENT_CHECK_H_

// The rules a segment must pass before it is stitched, in one place: its
// shapes and values against the run's spec and limits, a policy version
// that was published, and one recent enough to train on. A segment is
// checked once: the gateway checks what arrives over the network (so that
// its sender hears why), a local run's intake checks its own queue's.

#include <cstdint>

#include "absl/status/status.h"
#include "common/env/environment.h"
#include "common/rollout/segment.h"
#include "common/rollout/value_limits.h"

namespace vantage {

class SegmentCheck {
 public:
  // `max_policy_lag`: versions a segment may be behind the newest one
  // (0: only the newest, the sync mode; -1: any).
  // `core_state_size`: the floats of a recurrent policy's state each
  // segment carries (0: none).
  SegmentCheck(EnvSpec spec, int64_t max_segment_steps,
               ValueLimits value_limits, int64_t max_policy_lag,
               int64_t core_state_size = 0);

  // ValidateSegment against the run's spec and limits (the message names
  // the field).
  absl::Status Validate(const Segment& segment) const;
  // FailedPrecondition when `policy_version` is newer than `newest`.
  static absl::Status CheckPublished(int64_t policy_version, int64_t newest);
  // Whether a step acted by `policy_version` is too old to train a policy
  // at version `newest`.
  bool TooStale(int64_t policy_version, int64_t newest) const {
    return policy_version < OldestTrainable(newest);
  }
  // The oldest version whose steps still train at version `newest`.
  int64_t OldestTrainable(int64_t newest) const;
  int64_t max_policy_lag() const { return max_policy_lag_; }

 private:
  EnvSpec spec_;
  int64_t max_segment_steps_;
  ValueLimits value_limits_;
  int64_t max_policy_lag_;
  int64_t core_state_size_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_INGEST_SEGMENT_CHECK_H_
