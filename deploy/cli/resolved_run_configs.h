#ifndef VANTAGE_DEPLOY_CLI_RESOLVED_RUN_CONFIGS_H_
#define VANTAGE_DEPLOY_CLI_RESOLVED_RUN_CONFIGS_H_

// The run configs a figure or report script reads, as this vantage
// resolves them. A run made before a setting existed records no value for
// it in its config.json, and ran with the behaviour the setting's default
// keeps (a new setting's default is the old behaviour); read raw, the
// scripts would see the type's zero (false, 0) there and split such runs
// from identical newer ones.

#include <string>
#include <vector>

namespace vantage {

// The environment variable naming the file the scripts read: a JSON object
// from each run directory's real path to its resolved config.
inline constexpr char kResolvedRunConfigsVariable[] =
    "VANTAGE_RESOLVED_RUN_CONFIGS";

// Resolves (ResolveRunConfig) the config.json of every directory at or
// below the `arguments` that name directories, writes them to a memory file
// that stays open across exec and sets kResolvedRunConfigsVariable to its
// /proc/self/fd path. A config this vantage cannot read or refuses is left
// out (the script reads that run's file as it is, and reports what is
// wrong with it). Unsets the variable when there is nothing to write or the
// file cannot be made.
void ExportResolvedRunConfigs(const std::vector<std::string>& arguments);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_RESOLVED_RUN_CONFIGS_H_
