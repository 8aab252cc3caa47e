#ifndef VANTAGE_LEARNER_INGEST_ROLLOUT_STITCHER_H_
#define VANTAGE_LEARNER_INGEST_ROLLOUT_STITCHER_H_

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <deque>
#include <map>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "common/env/environment.h"
#include "common/rollout/segment.h"

namespace vantage {

// `horizon` consecutive steps of one (actor, env slot) stream, stitched
// across segment boundaries; episodes may end anywhere inside.
struct Rollout {
  int64_t actor_id = 0;
  int64_t env_slot = 0;
  at::Tensor observations;         // [T + 1, obs]; the last is s_T
  at::Tensor actions;              // [T, act]
  at::Tensor rewards;              // [T]
  at::Tensor terminated;           // [T] bool
  at::Tensor truncated;            // [T] bool
  at::Tensor final_observations;   // [K, obs] for the K truncated steps
  at::Tensor behaviour_log_probs;  // [T]
  at::Tensor policy_versions;      // [T] int64: the version that acted
  // A recurrent policy's state before step 0 [state size] (its first
  // segment's); undefined for a feed-forward policy.
  at::Tensor core_state;
  // Masked discrete actions: the legal actions at each step [T, actions]
  // bool; undefined otherwise.
  at::Tensor action_masks;
  // [T + 1] int64: the step of its episode each observation is (0 where
  // an episode starts); a truncated step's final observation is its
  // step's + 1.
  at::Tensor episode_steps;
};

struct StitcherStats {
  int64_t segments = 0;
  int64_t rollouts = 0;
  int64_t gaps = 0;            // a stream restarted (sequence jumped)
  int64_t dropped_steps = 0;   // buffered steps discarded at gaps
  int64_t stale_segments = 0;  // sequence at or below one already used
  int64_t stale_steps = 0;     // dropped as too old a policy version
  int64_t evicted_steps = 0;   // dropped to keep the buffers in budget
};

// Joins each stream's segments, in sequence order, into rollouts of exactly
// `horizon` steps. Nothing is stitched across a sequence gap: the buffered
// steps of the old stream are dropped and counted. Segments must have
// passed ValidateSegment.
class RolloutStitcher {
 public:
  explicit RolloutStitcher(int64_t horizon);

  // FailedPrecondition (counted) for a segment whose sequence was already
  // seen; the stream is unchanged.
  absl::Status Add(Segment segment);

  // The rollouts completed so far, oldest first.
  std::vector<Rollout> TakeReady();

  // Drops buffered steps acted by a policy version below `min_version`
  // (too stale to train on); the streams go on from their newer steps.
  // Returns the number of steps dropped (also in stats().stale_steps).
  int64_t DropStepsOlderThan(int64_t min_version);

  // Frees whole streams, the least recently fed first, until at most
  // `max_steps` steps stay buffered; the stream (actor_id, env_slot) is
  // spared (it is about to be fed). Returns the steps dropped (also in
  // stats().evicted_steps). What bounds a learner's buffers however many
  // streams its clients open.
  int64_t EvictDownTo(int64_t max_steps, int64_t actor_id, int64_t env_slot);

  // Frees every stream of `actor_id` (a registration that expired), with
  // its buffered steps; returns how many were dropped (also counted in
  // stats().dropped_steps). Its later segments would start new streams.
  int64_t ForgetActor(int64_t actor_id);
  // Streams with state, over all actors.
  size_t stream_count() const { return streams_.size(); }

  // Steps waiting in partial rollouts, over all streams.
  int64_t buffered_steps() const { return buffered_; }
  const StitcherStats& stats() const { return stats_; }

 private:
  struct Piece {
    std::shared_ptr<const Segment> segment;
    int64_t begin = 0;
    int64_t end = 0;
    // [T + 1] int64: the step of its episode each of the segment's
    // observations is, counted once when the segment arrives.
    at::Tensor episode_steps;
  };
  struct Stream {
    int64_t next_sequence = 0;
    bool started = false;
    std::deque<Piece> pieces;
    int64_t steps = 0;
    int64_t last_fed = 0;  // the Add count when it last got a segment
  };

  Rollout Cut(int64_t actor_id, int64_t env_slot, Stream& stream);

  const int64_t horizon_;
  std::map<std::pair<int64_t, int64_t>, Stream> streams_;
  std::vector<Rollout> ready_;
  StitcherStats stats_;
  int64_t adds_ = 0;
  int64_t buffered_ = 0;  // the sum of the streams' steps
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_INGEST_ROLLOUT_STITCHER_H_
