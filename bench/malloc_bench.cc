#include "bench/malloc_bench.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/util/self_process.h"

namespace vantage {
namespace {

struct Usage {
  double cpu_seconds = 0.0;
  double faults = 0.0;
  double peak_rss_mb = 0.0;
};

double Seconds(const timeval& t) { return t.tv_sec + t.tv_usec * 1e-6; }

// One run of the config as a child `vantage train`; with `glibc_defaults`
// its environment holds glibc's own default, which vantage then leaves
// alone. nullopt (the reason on stderr) if it failed.
std::optional<Usage> TimeRun(const MallocBenchConfig& config,
                             bool glibc_defaults) {
  const std::string run_dir =
      absl::StrCat(std::filesystem::temp_directory_path().string(),
                   "/vantage-bench-malloc-", ::getpid());
  const std::string log = run_dir + ".log";
  std::error_code error;
  std::filesystem::remove_all(run_dir, error);
  if (glibc_defaults) setenv("MALLOC_MMAP_MAX_", "65536", 1);
  absl::StatusOr<pid_t> train = SpawnSelf(
      {"train", "--config=" + config.config_path, "--run_dir=" + run_dir}, log);
  unsetenv("MALLOC_MMAP_MAX_");
  if (!train.ok()) {
    std::fprintf(stderr, "vantage bench malloc: %s\n",
                 std::string(train.status().message()).c_str());
    return std::nullopt;
  }
  int status = 0;
  rusage usage{};
  wait4(*train, &status, 0, &usage);
  std::filesystem::remove_all(run_dir, error);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr,
                 "vantage bench malloc: the run failed (its output is in "
                 "%s)\n",
                 log.c_str());
    return std::nullopt;
  }
  std::filesystem::remove(log, error);
  return Usage{Seconds(usage.ru_utime) + Seconds(usage.ru_stime),
               static_cast<double>(usage.ru_minflt), usage.ru_maxrss / 1024.0};
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

}  // namespace

int RunMallocBenchmark(const MallocBenchConfig& config) {
  std::printf(
      "bench malloc: %s, a batch's observations %.0f MB; each run with "
      "glibc's defaults, then with freed memory kept, %d times\n",
      config.env.c_str(), config.batch_observation_bytes / 1e6,
      config.repetitions);
  std::vector<Usage> glibc, kept;
  for (int repetition = 0; repetition < config.repetitions; ++repetition) {
    for (const bool defaults : {true, false}) {
      std::optional<Usage> usage = TimeRun(config, defaults);
      if (!usage) return 1;
      std::printf("  %-22s CPU %7.1f s, %9.0f page faults, peak RSS %6.0f MB\n",
                  defaults ? "glibc's defaults:" : "freed memory kept:",
                  usage->cpu_seconds, usage->faults, usage->peak_rss_mb);
      std::fflush(stdout);
      (defaults ? glibc : kept).push_back(*usage);
    }
  }
  auto median = [](const std::vector<Usage>& runs, double Usage::*field) {
    std::vector<double> values;
    for (const Usage& run : runs) values.push_back(run.*field);
    return Median(values);
  };
  const double glibc_cpu = median(glibc, &Usage::cpu_seconds);
  const double kept_cpu = median(kept, &Usage::cpu_seconds);
  std::printf(
      "RESULT malloc env=%s glibc_cpu_s=%.1f kept_cpu_s=%.1f "
      "glibc_faults=%.0f kept_faults=%.0f glibc_peak_rss_mb=%.0f "
      "kept_peak_rss_mb=%.0f ratio=%.2f\n",
      config.env.c_str(), glibc_cpu, kept_cpu, median(glibc, &Usage::faults),
      median(kept, &Usage::faults), median(glibc, &Usage::peak_rss_mb),
      median(kept, &Usage::peak_rss_mb), glibc_cpu / kept_cpu);
  return 0;
}

}  // namespace vantage
