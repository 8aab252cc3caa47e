#ifndef VANTAGE_DEPLOY_RUN_LOCAL_TRAINING_H_
#define VANTAGE_DEPLOY_RUN_LOCAL_TRAINING_H_

#include <atomic>
#include <functional>

#include "absl/status/status.h"
#include "deploy/run/run_plan.h"
#include "learner/run/progress_columns.h"

namespace vantage {

// `--mode=local`: the plan's actor core and learner core in this process,
// connected by an in-process queue, strictly on-policy: the actor collects
// one horizon per environment with the latest weights, the learner updates
// and publishes the next version. `on_update` sees every update (after its
// progress row and checkpoint are written) and returns false to stop the
// run there, as an interruption would (a later resume continues it). Once
// `stop` (if given) is set, the run stops after the update in progress with
// a checkpoint of it, as a signalled learner does, and returns OK.
absl::Status RunLocalTraining(
    const RunPlan& plan,
    const std::function<bool(const ProgressRow&)>& on_update,
    const std::atomic<bool>* stop = nullptr);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_LOCAL_TRAINING_H_
