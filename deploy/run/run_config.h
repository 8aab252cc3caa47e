#ifndef VANTAGE_DEPLOY_RUN_RUN_CONFIG_H_
#define VANTAGE_DEPLOY_RUN_RUN_CONFIG_H_

// A training run's settings (proto/run_config.proto) resolved: defaults
// and checks (their files: run_config_file.h; the component configs they
// turn into: run_plan.h).

#include <string>

#include "absl/status/statusor.h"
#include "actor/run_settings.h"  // EnvOptionsOf, for the run's env makers
#include "deploy/run/run_config_file.h"
#include "proto/run_config.pb.h"

namespace vantage {

// Fills every absent field of the run's sections with its default (taken
// from the component that owns it: ActorConfig, LearnerConfig,
// RecordingConfig, AdvantageConfig, NetworkConfig, the algorithm's config
// and its AlgorithmRunDefaults) and checks every value; a message names the
// field by its `vantage train` flag. deploy/run/run_plan.h turns the result
// into the configs of the parts that run it.
absl::StatusOr<pb::RunConfig> ResolveRunConfig(const pb::RunConfig& given);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_RUN_CONFIG_H_
