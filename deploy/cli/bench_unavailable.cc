// `vantage bench` in a binary built without the benchmarks (what the first
// command of the README builds): it says how to build them.

#include "deploy/cli/bench_command.h"

namespace vantage {

Command BenchCommand() {
  Command command;
  command.name = "bench";
  command.summary = "benchmarks (not in this build: deploy/setup.sh --tests)";
  command.usage = "vantage bench NAME";
  command.description =
      "This vantage was built without its benchmarks. `deploy/setup.sh\n"
      "--tests` builds them with the tests (or configure with\n"
      "-DVANTAGE_BUILD_BENCHMARKS=ON).";
  command.takes_arguments = true;
  command.run = [](const std::vector<std::string>&) {
    return CommandFailure(
        "bench", kUsageError,
        "this binary was built without the benchmarks; build them with "
        "`deploy/setup.sh --tests` (or -DVANTAGE_BUILD_BENCHMARKS=ON)");
  };
  return command;
}

}  // namespace vantage
