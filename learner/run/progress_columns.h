#ifndef VANTAGE_LEARNER_RUN_PROGRESS_COLUMNS_H_
#define VANTAGE_LEARNER_RUN_PROGRESS_COLUMNS_H_

// The statistics of one update, as progress.csv's columns and as the
// learner's Prometheus series: one table feeds both, so a statistic added
// here is in the file and on the dashboard alike.

#include <optional>
#include <string>
#include <vector>

#include "common/rollout/policy_evaluation.h"
#include "learner/update/update_stats.h"

namespace vantage {

struct ProgressRow {
  UpdateStats stats;
  double mean_return = 0.0;       // last 100 episodes; NaN: none finished yet
  double elapsed_seconds = 0.0;   // of the whole run, across resumes
  double steps_per_second = 0.0;  // since this process started
  // An evaluation that finished since the previous row (of this update's
  // version in a local run, of an earlier one in a distributed run).
  std::optional<EvaluationSummary> evaluation;
};

struct ProgressColumn {
  enum class Format { kInteger, kNumber, kMilliseconds, kTenths };
  // How the learner exports the column after every update: a gauge set to
  // the row's value, or a counter fed from it as a running total.
  enum class Metric { kGauge, kCounter };

  const char* name;    // progress.csv header
  const char* metric;  // series name after "vantage_learner_"
  Metric kind;
  Format format;
  const char* help;
  double (*value)(const ProgressRow& row);
};

// In progress.csv order. Every column but the last two (wall-clock)
// repeats exactly for the same seed and flags.
const std::vector<ProgressColumn>& ProgressColumns();

// "env_steps,updates,...,sps" (no newline).
std::string ProgressHeader();
// The CSV line (no newline); NaN values are empty fields.
std::string FormatProgressRow(const ProgressRow& row);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_PROGRESS_COLUMNS_H_
