#ifndef VANTAGE_ACTOR_EVALUATION_CONFIG_H_
#define VANTAGE_ACTOR_EVALUATION_CONFIG_H_

// How often a run evaluates its deterministic policy, and on how many
// episodes (actor/policy_evaluator.h runs them; the learner records them).

#include <cstdint>

#include "absl/status/status.h"
#include "proto/run_config.pb.h"

namespace vantage {

struct EvaluationConfig {
  int64_t every = 0;  // updates between evaluations; 0: none
  int episodes = 10;

  bool enabled() const { return every > 0; }
  // every >= 0, episodes >= 1 (the message names the flag).
  absl::Status Validate() const;
};

// The run config's evaluation section with its settings resolved, checked
// (the message names the flag), and in the config only when --eval_every
// is above 0, so that a run without evaluations has the config it had
// before they existed; --eval_episodes without it is an error.
absl::Status ResolveEvaluationSettings(pb::RunConfig& run);
// The run's evaluations (none without the section).
EvaluationConfig EvaluationConfigOf(const pb::RunConfig& run);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_EVALUATION_CONFIG_H_
