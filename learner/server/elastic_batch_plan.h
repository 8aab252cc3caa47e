#ifndef VANTAGE_LEARNER_SERVER_ELASTIC_BATCH_PLAN_H_
#define VANTAGE_LEARNER_SERVER_ELASTIC_BATCH_PLAN_H_

// The batch of a learner that serves a pool of remote actors, which come
// and go. Each version's grant (ActorGateway::Publish) shares the batch's
// rollouts out over the env slots live when it is published; then:
// - sync: the batch is every rollout of the version from every actor, and
//   it is complete once each actor that is live (has a call open) has sent
//   its grant and the whole holds at least the batch's rollouts. An actor
//   that joins during the version takes the grant in force and is waited
//   for; one that leaves (its calls end, or it stalls and expires) is not,
//   and what it sent stays in. If the live actors have all sent their
//   grant and the batch is still short (some left), the version is granted
//   again with as many more horizons per live slot as fill it. Once
//   complete the grant goes to 0, so that an actor joining before the next
//   version waits for it instead of acting for a batch already taken.
//   Which rollouts make a batch is therefore defined by who is live, never
//   by arrival order, and no rollout of the version is left over as stale.
// - asynchronous: the batch is the oldest `batch_rollouts` rollouts held
//   (the rest wait for the next, within the policy-lag bound); when every
//   live actor has sent all its grant allows and the queue is empty yet
//   the batch is short, the grant grows as above.
// A raise waits while fewer env slots are live than the run plans (its
// distributed.actors x envs_per_actor) until that has lasted kRaiseGrace:
// actors starting together all take part in the first batches, as they
// would with a fixed pool, so that such a run repeats exactly; an actor
// lost mid-run delays the batch by that much once. With no actor live the
// learner waits.

#include <cstdint>
#include <functional>
#include <map>

#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "learner/ingest/batch_plan.h"
#include "learner/service/actor_gateway.h"

namespace vantage {

class ElasticBatchPlan : public BatchPlan {
 public:
  static constexpr absl::Duration kRaiseGrace = absl::Seconds(5);

  // `planned_slots`: the env slots the run plans for this learner;
  // `queued`: the segments admitted but not yet received by the intake.
  ElasticBatchPlan(ActorGateway& gateway, bool sync, int64_t batch_rollouts,
                   int64_t planned_slots, std::function<int64_t()> queued,
                   absl::Duration raise_grace = kRaiseGrace);

  int64_t BatchSize(int64_t version, const std::map<int64_t, int64_t>& held,
                    int64_t total) override;

  // Grants raised because the live actors could not fill a batch.
  int64_t raises() const { return raises_; }

 private:
  int64_t SyncBatchSize(int64_t version, const PoolView& pool,
                        const std::map<int64_t, int64_t>& held, int64_t total);
  int64_t AsyncBatchSize(const PoolView& pool, int64_t total);
  // Grants the live slots as many more horizons as `missing` rollouts need
  // (once a shortfall of live slots has lasted kRaiseGrace).
  void Raise(const PoolView& pool, int64_t missing);

  ActorGateway& gateway_;
  const bool sync_;
  const int64_t batch_rollouts_;
  const int64_t planned_slots_;
  const std::function<int64_t()> queued_;
  const absl::Duration raise_grace_;
  absl::Time short_since_ = absl::InfiniteFuture();
  int64_t raises_ = 0;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_SERVER_ELASTIC_BATCH_PLAN_H_
