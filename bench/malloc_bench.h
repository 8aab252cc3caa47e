#ifndef VANTAGE_BENCH_MALLOC_BENCH_H_
#define VANTAGE_BENCH_MALLOC_BENCH_H_

#include <cstdint>
#include <string>

namespace vantage {

// One short local training run to time both ways.
struct MallocBenchConfig {
  std::string config_path;  // its resolved run config (a --config file)
  std::string env;
  int64_t batch_observation_bytes = 0;  // one batch's, as floats
  int repetitions = 2;
};

// `vantage bench malloc`: the run (`vantage train`, a child process) with
// glibc's malloc defaults (MALLOC_MMAP_MAX_=65536 in its environment) and
// with what vantage sets for batches above glibc's largest mmap threshold
// (learner/run/batch_memory.h: freed memory kept for reuse), alternately,
// `repetitions` times each; their CPU time (user + system), minor page
// faults and peak resident memory, from wait4. Ends with `RESULT malloc
// env=.. glibc_cpu_s=.. kept_cpu_s=.. glibc_faults=.. kept_faults=..
// glibc_peak_rss_mb=.. kept_peak_rss_mb=.. ratio=<glibc / kept CPU time>`
// (medians). Exit 1 if a run failed.
int RunMallocBenchmark(const MallocBenchConfig& config);

}  // namespace vantage

#endif  // VANTAGE_BENCH_MALLOC_BENCH_H_
