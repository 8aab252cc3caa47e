#ifndef VANTAGE_COMMON_UTIL_SELF_PROCESS_H_
#define VANTAGE_COMMON_UTIL_SELF_PROCESS_H_

// Child processes of this same binary (`vantage <command> ...`): how the
// launcher starts learners and actors and the benchmarks their peers.

#include <sys/types.h>

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace vantage {

// Runs this binary with `args` (argv[1..]) as a child process (the very
// file this process runs, though the path now holds another); with
// `output_path`, its stdout and stderr go to that file (truncated, or
// appended to with `append`).
absl::StatusOr<pid_t> SpawnSelf(const std::vector<std::string>& args,
                                const std::string& output_path = "",
                                bool append = false);

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_SELF_PROCESS_H_
