#include "learner/server/elastic_batch_plan.h"

#include <cstdio>
#include <utility>

namespace vantage {

ElasticBatchPlan::ElasticBatchPlan(ActorGateway& gateway, bool sync,
                                   int64_t batch_rollouts,
                                   int64_t planned_slots,
                                   std::function<int64_t()> queued,
                                   absl::Duration raise_grace)
    : gateway_(gateway),
      sync_(sync),
      batch_rollouts_(batch_rollouts),
      planned_slots_(planned_slots),
      queued_(std::move(queued)),
      raise_grace_(raise_grace) {}

int64_t ElasticBatchPlan::BatchSize(int64_t version,
                                    const std::map<int64_t, int64_t>& held,
                                    int64_t total) {
  const PoolView pool = gateway_.Pool();
  if (pool.live_env_slots() >= planned_slots_) {
    short_since_ = absl::InfiniteFuture();
  } else if (short_since_ == absl::InfiniteFuture()) {
    short_since_ = absl::Now();
  }
  // A version the gateway has not published yet (or no longer holds) has
  // no grant to judge by.
  if (pool.version != version) {
    return !sync_ && total >= batch_rollouts_ ? batch_rollouts_ : 0;
  }
  return sync_ ? SyncBatchSize(version, pool, held, total)
               : AsyncBatchSize(pool, total);
}

int64_t ElasticBatchPlan::SyncBatchSize(int64_t version, const PoolView& pool,
                                        const std::map<int64_t, int64_t>& held,
                                        int64_t total) {
  // Every sync rollout held is of `version` (older ones were stale).
  for (const PoolView::Member& member : pool.members) {
    auto it = held.find(member.actor_id);
    const int64_t sent = it == held.end() ? 0 : it->second;
    if (sent < pool.horizons * member.env_slots) return 0;
  }
  if (total >= batch_rollouts_) {
    gateway_.Grant(version, 0);
    return total;
  }
  Raise(pool, batch_rollouts_ - total);
  return 0;
}

int64_t ElasticBatchPlan::AsyncBatchSize(const PoolView& pool, int64_t total) {
  if (total >= batch_rollouts_) return batch_rollouts_;
  for (const PoolView::Member& member : pool.members) {
    if (member.owed_steps > 0) return 0;
  }
  if (queued_() == 0) Raise(pool, batch_rollouts_ - total);
  return 0;
}

void ElasticBatchPlan::Raise(const PoolView& pool, int64_t missing) {
  const int64_t slots = pool.live_env_slots();
  if (slots == 0) return;  // nobody to ask: wait for actors
  if (short_since_ != absl::InfiniteFuture() &&
      absl::Now() - short_since_ < raise_grace_) {
    return;
  }
  ++raises_;
  const int64_t horizons = pool.horizons + (missing + slots - 1) / slots;
  gateway_.Grant(pool.version, horizons);
  std::fprintf(stderr,
               "learner: %zu actors with %ld env slots are live (the run plans "
               "%ld) and have sent their grant, %ld rollouts short of the "
               "batch: version %ld now grants %ld horizons per slot\n",
               pool.members.size(), static_cast<long>(slots),
               static_cast<long>(planned_slots_), static_cast<long>(missing),
               static_cast<long>(pool.version), static_cast<long>(horizons));
}

}  // namespace vantage
