#ifndef VANTAGE_LEARNER_UPDATE_UPDATE_STATS_H_
#define VANTAGE_LEARNER_UPDATE_UPDATE_STATS_H_

// What one update of the learner reports, without LibTorch: progress.csv,
// the metrics and the command line read it.

#include <cstdint>
#include <string>
#include <vector>

#include "learner/algorithms/algorithm_stats.h"
#include "learner/exploration/exploration_stats.h"

namespace vantage {

// Over the global batch (every replica's) in a data-parallel run.
struct UpdateStats {
  int64_t policy_version = 0;  // published after this update
  int64_t env_steps = 0;       // consumed so far
  int64_t episodes = 0;        // finished, reported by consumed segments
  // Of the last 100 episodes each replica saw; NaN before the first ends.
  double mean_return = 0.0;
  AlgorithmStats algorithm;
  ExplorationStats exploration;  // rank 0's, in a data-parallel run
  double biased_fraction = 0.0;  // share of samples using the bias
  double mean_abs_bias = 0.0;    // mean |biased - GAE|
  double explained_variance = 0.0;
  int64_t rejected_segments = 0;  // so far, any reason (stale included)
  // Why the first segment this update refused was refused (what
  // ValidateSegment or the stitcher said, with the segment's actor and
  // slot); empty if it refused none. Stale segments are only counted.
  std::string first_rejection;
  int64_t stale_segments = 0;  // so far, too old a policy version
  int64_t stale_steps = 0;     // so far, dropped for their version
  int64_t evicted_steps = 0;   // so far, dropped to stay in budget
  // This update produced a non-finite loss or parameter (or too large a
  // gradient) and was undone: the networks, the optimiser state and the
  // reward scaler are as before it, the batch is dropped, the version still
  // advances (with unchanged weights) so that synchronous actors go on.
  bool rolled_back = false;
  std::string rollback_reason;      // why, if rolled_back
  int64_t rolled_back_updates = 0;  // so far
  // Wall-clock seconds of this update once its batch was complete (not
  // reproducible, so not in progress.csv).
  double update_seconds = 0.0;
  // Of which: the critic's values and the advantages (batch assembly
  // included), and the algorithm's optimisation.
  double advantage_seconds = 0.0;
  double optimisation_seconds = 0.0;
  // Who fed this batch: the actors and the env streams (actor, slot) of its
  // rollouts (a learner's own share, with data-parallel replicas).
  int64_t batch_actors = 0;
  int64_t batch_env_slots = 0;
  // Per rollout of this batch: how many versions behind the updated policy
  // its oldest step was acted (0 throughout in sync mode).
  std::vector<int64_t> rollout_policy_lags;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_UPDATE_UPDATE_STATS_H_
