#ifndef VANTAGE_DEPLOY_RUN_RUN_CONFIG_FILE_H_
#define VANTAGE_DEPLOY_RUN_RUN_CONFIG_FILE_H_

// A run config as a file: config.json and --config files (JSON), the flat
// format of older runs, and how two configs differ.

#include <string>

#include "absl/status/statusor.h"
#include "proto/run_config.pb.h"

namespace vantage {

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

#endif  // VANTAGE_DEPLOY_RUN_RUN_CONFIG_FILE_H_
