#ifndef VANTAGE_BENCH_FASTEST_H_
#define VANTAGE_BENCH_FASTEST_H_

// How every vantage benchmark measures on a shared, noisy machine: many
// short repetitions, interleaved across benchmarks (the default the
// `vantage` tool sets), and the fastest one kept, since interference only
// ever adds time.

#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace vantage {

// 30 repetitions of at least 0.05 s each, reported as aggregates with a
// "min" statistic.
void UseFastestOfRepetitions(benchmark::internal::Benchmark* benchmark);

// For work that takes long per iteration (a whole learner update): single
// iterations, `repetitions` of them, the fastest kept.
void UseFastestOfSingleRuns(benchmark::internal::Benchmark* benchmark,
                            int repetitions);

// Prints as the console reporter does and records each benchmark's fastest
// repetition (seconds per iteration).
// Colours only on a terminal: Google Benchmark's console reporter colours
// by default, and its escape codes in a pipe would precede the RESULT lines
// that scripts read.
class FastestCollector : public benchmark::ConsoleReporter {
 public:
  FastestCollector();
  void ReportRuns(const std::vector<Run>& runs) override;
  // -1 if the benchmark did not run.
  double Seconds(const std::string& name) const;

 private:
  std::map<std::string, double> seconds_;
};

}  // namespace vantage

#endif  // VANTAGE_BENCH_FASTEST_H_
