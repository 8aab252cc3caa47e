#ifndef VANTAGE_LEARNER_EXPLORATION_EXPLORATION_STATS_H_
#define VANTAGE_LEARNER_EXPLORATION_EXPLORATION_STATS_H_

#include <cstdint>
#include <limits>
#include <string>

namespace vantage {

// What an exploration bonus did in one update (this replica's batch in a
// data-parallel run). All NaN in a run without one.
struct ExplorationStats {
  // Means over this update's Adam steps of the density model; NaN if it
  // did not fit this update.
  double model_loss = std::numeric_limits<double>::quiet_NaN();
  double model_accuracy = std::numeric_limits<double>::quiet_NaN();
  // Mean bonus over the batch before centring and weighting (0 until the
  // model is in use).
  double mean_bonus = std::numeric_limits<double>::quiet_NaN();
  // Its standard deviation over the batch: how much the bonus tells the
  // batch's states apart, which the model's accuracy does not say (a
  // discriminator right on 99% of pairs can still rank states).
  double bonus_std = std::numeric_limits<double>::quiet_NaN();
  int64_t fit_steps = 0;
  // Why this update must be undone (a non-finite bonus: the model
  // diverged); empty if nothing is wrong.
  std::string fault;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_EXPLORATION_EXPLORATION_STATS_H_
