#ifndef VANTAGE_DEPLOY_CLI_RUN_FLAGS_H_
#define VANTAGE_DEPLOY_CLI_RUN_FLAGS_H_

// The flags that describe a training run (proto/run_config.proto), read by
// `vantage train` and `vantage learner`: one flag per field of the run's
// sections, named as the field (an algorithm's fields prefixed with the
// algorithm: ppo.epochs is --ppo_epochs), --algo choosing the algorithm,
// plus --config, --run_dir and --resume.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "deploy/cli/command.h"
#include "deploy/cli/run_request.h"

namespace vantage {

// The run flags of run-config fields with a `flag` option, for the
// commands that take them to declare (Command::declared_flags); a value is
// checked as the field reads it.
std::vector<DeclaredFlag> RunSettingFlags();

// The names of the run flags in the order of their sections; `with_mode`
// adds --mode (train only: a learner is always the distributed one).
std::vector<std::string> RunFlagNames(bool with_mode);

// What each absent run flag means, from ResolveRunConfig itself; a default
// that depends on the algorithm lists each one's, and `with_mode` adds what
// differs under --mode=local.
std::map<std::string, std::string> RunFlagDefaults(bool with_mode);

// A resolved field's value as its flag would spell it ("" when absent or
// unknown); `flag` is the flag's name (e.g. "horizon", "ppo_epochs").
std::string RunConfigFieldText(const pb::RunConfig& config,
                               const std::string& flag);

// The given run flags; an unparsable value, or a setting of an algorithm
// other than --algo's, is an error naming the flag.
absl::StatusOr<RunRequest> RunRequestFromFlags();

// The same from (flag name, value as on a command line) pairs, as an
// experiment's cells set them; a name that is no run flag is an error that
// lists them. Only `flags`, `algo` and `given_flags` are filled.
absl::StatusOr<RunRequest> RunRequestFromSettings(
    const std::vector<std::pair<std::string, std::string>>& settings);

// The flags a run setting may name: --algo and one per run-config field
// (not --config, --run_dir or --resume).
std::vector<std::string> RunSettingNames();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_RUN_FLAGS_H_
