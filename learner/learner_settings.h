#ifndef VANTAGE_LEARNER_LEARNER_SETTINGS_H_
#define VANTAGE_LEARNER_LEARNER_SETTINGS_H_

// What a learner takes from a run's configuration: its batch, budget and
// reward scaling (the training section's), its estimator (the advantage
// section), its algorithm and exploration. One reading for every caller,
// the learner's settings declared once in the tables of
// learner_settings.cc, as an actor's are in actor/run_settings.cc.

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "learner/algorithms/run_defaults.h"
#include "learner/learner_config.h"
#include "proto/run_config.pb.h"

namespace vantage {

// The training section's learner settings (horizon, steps, scale_rewards)
// resolved over `defaults`, and the horizon the algorithm fixes (a2c's)
// enforced.
absl::Status ResolveLearnerTraining(const LearnerConfig& defaults,
                                    const AlgorithmRunDefaults& algorithm,
                                    const std::string& algorithm_name,
                                    pb::TrainingSettings& training);

// The advantage section with every absent setting given its default (GAE
// lambda: the algorithm's); the estimator's name checked. Its numbers are
// checked by AdvantageConfig::Validate once the config is whole.
absl::Status ResolveAdvantageSettings(const AlgorithmRunDefaults& algorithm,
                                      pb::AdvantageSettings& advantage);

// The learner of a resolved run config: everything but the environment's
// spec and what it shares with the actors (its network and observation
// clip, which the run's plan copies from the actor's).
absl::StatusOr<LearnerConfig> LearnerConfigOf(const pb::RunConfig& run);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_LEARNER_SETTINGS_H_
