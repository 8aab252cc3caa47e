#ifndef VANTAGE_DEPLOY_RUN_RUN_CONFIG_H_
#define VANTAGE_DEPLOY_RUN_RUN_CONFIG_H_

// A training run's settings (proto/run_config.proto): defaults, checks,
// JSON files, and the component configs they turn into.

#include <string>

#include "absl/status/statusor.h"
#include "actor/run_settings.h"  // EnvOptionsOf, for the run's env makers
#include "proto/run_config.pb.h"

namespace vantage {

// Fills every absent field of the run's sections with its default (taken
// from the component that owns it: ActorConfig, LearnerConfig,
// RecordingConfig, AdvantageConfig, NetworkConfig, the algorithm's config
// and its AlgorithmRunDefaults) and checks every value; a message names the
// field by its `vantage train` flag. deploy/run/run_plan.h turns the result
// into the configs of the parts that run it.
absl::StatusOr<pb::RunConfig> ResolveRunConfig(const pb::RunConfig& given);

// Parses a JSON RunConfig (unknown keys and wrong types are errors). A
// config.json in the flat format of older runs is converted (see
// proto/flat_run_config.proto), so their run directories and checkpoints
// still load.
absl::StatusOr<pb::RunConfig> ReadRunConfigFile(const std::string& path);
absl::StatusOr<pb::RunConfig> ParseRunConfigJson(const std::string& json);
// Every field, with the proto's field names.
std::string RunConfigToJson(const pb::RunConfig& config);
// The first field in which two configs differ, as MessageDifferencer words
// it ("modified: training.steps: 300000 -> 150000", from `held` to
// `wanted`); empty when they are equal.
std::string RunConfigDifference(const pb::RunConfig& held,
                                const pb::RunConfig& wanted);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_RUN_CONFIG_H_
