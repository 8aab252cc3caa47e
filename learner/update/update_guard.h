#ifndef VANTAGE_LEARNER_UPDATE_UPDATE_GUARD_H_
#define VANTAGE_LEARNER_UPDATE_UPDATE_GUARD_H_

// Defence in depth around one update: whatever passed validation, an update
// that produces non-finite numbers (or an exploding gradient) is undone, so
// that non-finite weights are never published or checkpointed.

#include <ATen/core/Tensor.h>

#include <string>
#include <vector>

#include "learner/algorithms/policy_updater.h"

namespace vantage {

class PolicyNetworkImpl;
class ValueNetworkImpl;
class RewardScaler;
class Ex2Bonus;

class UpdateGuard {
 public:
  // Keeps what the update may change: both networks' parameters, the
  // updater's optimiser state and, if given, the reward scaler's state and
  // the exploration model's (whose pool changes only once the update is
  // good). All must outlive the guard.
  UpdateGuard(PolicyNetworkImpl& policy, ValueNetworkImpl& value,
              PolicyUpdater& updater, RewardScaler* reward_scaler,
              Ex2Bonus* exploration = nullptr);

  // Why the networks may not be published after the update that returned
  // `stats`: a non-finite loss or parameter (the exploration model's
  // included), or a gradient norm above
  // `max_gradient_norm` (NaN norms, of algorithms without gradient steps,
  // never exceed it); empty if there is nothing wrong.
  std::string Fault(const AlgorithmStats& stats,
                    double max_gradient_norm) const;

  // Puts back everything kept at construction.
  void Restore();

 private:
  PolicyNetworkImpl& policy_;
  ValueNetworkImpl& value_;
  PolicyUpdater& updater_;
  RewardScaler* reward_scaler_;
  Ex2Bonus* exploration_;
  std::vector<at::Tensor> parameters_;  // policy's, then value's
  std::string updater_state_;
  std::string reward_scaler_state_;
  std::string exploration_state_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_UPDATE_UPDATE_GUARD_H_
