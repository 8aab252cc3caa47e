#ifndef VANTAGE_LEARNER_INGEST_BATCH_PLAN_H_
#define VANTAGE_LEARNER_INGEST_BATCH_PLAN_H_

// When the rollouts the intake holds make a batch. Without a plan a batch is
// a fixed number of rollouts (a local run's own actor fills it exactly); a
// learner serving remote actors plans with its pool of live actors (see
// learner/server/elastic_batch_plan.h).

#include <cstdint>
#include <map>

#include "absl/time/time.h"

namespace vantage {

class BatchPlan {
 public:
  virtual ~BatchPlan() = default;

  // `held`: the complete rollouts waiting, per actor id, every one
  // trainable at `version`; `total`: their sum. Returns how many of them,
  // oldest first, make the batch now; 0: not yet. Asked after every
  // segment and, while none arrive, every recheck_interval().
  virtual int64_t BatchSize(int64_t version,
                            const std::map<int64_t, int64_t>& held,
                            int64_t total) = 0;
  virtual absl::Duration recheck_interval() const {
    return absl::Milliseconds(100);
  }
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_INGEST_BATCH_PLAN_H_
