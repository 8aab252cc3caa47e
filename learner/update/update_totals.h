#ifndef VANTAGE_LEARNER_UPDATE_UPDATE_TOTALS_H_
#define VANTAGE_LEARNER_UPDATE_UPDATE_TOTALS_H_

// The statistics of one update over the global batch: each replica's sums,
// added over every replica in one collective, and what progress.csv shows
// of them.

#include "learner/algorithms/algorithm_stats.h"
#include "learner/batch/batch_preparer.h"
#include "learner/ingest/segment_intake.h"
#include "learner/update/update_stats.h"

namespace vantage {

class ReplicaGroup;

struct UpdateSums {
  double samples = 0, episodes = 0, rejected = 0, stale_segments = 0,
         stale_steps = 0, evicted_steps = 0;
  double return_sum = 0, return_count = 0;  // of the last-100 windows
  double biased_samples = 0, abs_bias_sum = 0;
  // Of the value targets and of their residuals to the critic's values.
  double target_sum = 0, target_squares = 0, residual_sum = 0,
         residual_squares = 0;
  double policy_loss = 0, value_loss = 0, entropy = 0, approx_kl = 0,
         clip_fraction = 0;

  // This replica's: its batch, its algorithm's statistics and what its
  // intake counted since the last update.
  static UpdateSums Of(const PreparedBatch& prepared,
                       const AlgorithmStats& algorithm,
                       const SegmentIntake& intake);
  // Added over `replicas` (one collective).
  UpdateSums Over(ReplicaGroup& replicas) const;

  // The algorithm's statistics as means over `world_size` replicas.
  void AlgorithmMeans(double world_size, AlgorithmStats& algorithm) const;
  // The batch's statistics: mean return, biased fraction, mean |bias| and
  // the critic's explained variance.
  void BatchStatistics(UpdateStats& stats) const;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_UPDATE_UPDATE_TOTALS_H_
