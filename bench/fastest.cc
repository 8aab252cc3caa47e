#include "bench/fastest.h"

#include <unistd.h>

#include <algorithm>

namespace vantage {

namespace {

void ReportFastest(benchmark::internal::Benchmark* benchmark) {
  benchmark->ReportAggregatesOnly(true)->ComputeStatistics(
      "min", [](const std::vector<double>& times) {
        return *std::min_element(times.begin(), times.end());
      });
}

}  // namespace

void UseFastestOfRepetitions(benchmark::internal::Benchmark* benchmark) {
  benchmark->MinTime(0.05)->Repetitions(30)->Unit(benchmark::kMicrosecond);
  ReportFastest(benchmark);
}

void UseFastestOfSingleRuns(benchmark::internal::Benchmark* benchmark,
                            int repetitions) {
  benchmark->Iterations(1)
      ->Repetitions(repetitions)
      ->Unit(benchmark::kMillisecond);
  ReportFastest(benchmark);
}

FastestCollector::FastestCollector()
    : ConsoleReporter(::isatty(STDOUT_FILENO) == 1 ? OO_ColorTabular
                                                   : OO_Tabular) {}

void FastestCollector::ReportRuns(const std::vector<Run>& runs) {
  for (const Run& run : runs) {
    if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "min") {
      seconds_[run.run_name.function_name] =
          run.GetAdjustedRealTime() /
          benchmark::GetTimeUnitMultiplier(run.time_unit);
    }
  }
  ConsoleReporter::ReportRuns(runs);
}

double FastestCollector::Seconds(const std::string& name) const {
  auto it = seconds_.find(name);
  return it == seconds_.end() ? -1.0 : it->second;
}

}  // namespace vantage
