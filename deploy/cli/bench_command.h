#ifndef VANTAGE_DEPLOY_CLI_BENCH_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_BENCH_COMMAND_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage bench NAME`: the Google Benchmark suites of bench/, each ending
// with a `RESULT NAME ...` line of ratios against a baseline measured in
// the same run. Only built with the benchmarks (VANTAGE_BUILD_BENCHMARKS).
Command BenchCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_BENCH_COMMAND_H_
