#ifndef VANTAGE_ACTOR_ENVS_MEMORY_CUE_RECALL_H_
#define VANTAGE_ACTOR_ENVS_MEMORY_CUE_RECALL_H_

// CueRecall, a task that only memory solves: the first observation of an
// episode shows one of `cues` cues; `delay` blank observations follow;
// then an observation asks for it, and the action that names the cue
// earns 1 (any other 0) and ends the episode. Observations are
// [one-hot cue (cues), cue shown, recall now]: the one that asks is the
// same whatever the cue, so a policy that sees only the current
// observation is right 1 time in `cues`, and a policy that remembers is
// right every time. Actions during the delay do nothing.
//
// Options (`CueRecall:cues=8,delay=30`): cues (>= 2, default 4) and delay
// (>= 0 steps, default 10).

#include <memory>

#include "absl/status/statusor.h"
#include "actor/envs/env_options.h"
#include "common/env/environment.h"

namespace vantage {

absl::StatusOr<std::unique_ptr<Environment>> MakeCueRecall(const EnvName& name);
std::vector<EnvOptionInfo> CueRecallOptions();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MEMORY_CUE_RECALL_H_
