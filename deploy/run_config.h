#ifndef VANTAGE_DEPLOY_RUN_CONFIG_H_
#define VANTAGE_DEPLOY_RUN_CONFIG_H_

// A training run's settings (proto/run_config.proto): defaults, checks,
// JSON files, and the component configs they turn into.

#include <string>

#include "absl/status/statusor.h"
#include "deploy/local_training.h"
#include "proto/run_config.pb.h"

namespace vantage {

// Fills every absent field with its default (some depend on the
// algorithm) and checks every value; the message names the field as the
// `vantage train` flag of the same name.
absl::StatusOr<pb::RunConfig> ResolveRunConfig(const pb::RunConfig& given);

// Parses a JSON RunConfig (unknown keys and wrong types are errors).
absl::StatusOr<pb::RunConfig> ReadRunConfigFile(const std::string& path);
absl::StatusOr<pb::RunConfig> ParseRunConfigJson(const std::string& json);
// Every field, with the proto's field names.
std::string RunConfigToJson(const pb::RunConfig& config);

// The local training a resolved config describes.
LocalTrainingConfig ToLocalTrainingConfig(const pb::RunConfig& resolved);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_CONFIG_H_
