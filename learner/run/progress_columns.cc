#include "learner/run/progress_columns.h"

#include <cmath>
#include <cstdint>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace vantage {
namespace {

using Format = ProgressColumn::Format;
using Metric = ProgressColumn::Metric;

std::string FormatValue(Format format, double value) {
  switch (format) {
    case Format::kInteger:
      return absl::StrCat(static_cast<int64_t>(value));
    case Format::kNumber:
      return std::isnan(value) ? "" : absl::StrFormat("%.9g", value);
    case Format::kMilliseconds:
      return absl::StrFormat("%.3f", value);
    case Format::kTenths:
      return absl::StrFormat("%.1f", value);
  }
  return "";
}

std::vector<ProgressColumn> RunProgressColumns() {
  return {
      {"env_steps", "env_steps_total", Metric::kCounter, Format::kInteger,
       "Environment steps consumed by updates.",
       [](const ProgressRow& r) { return double(r.stats.env_steps); }},
      {"updates", "policy_version", Metric::kGauge, Format::kInteger,
       "Newest published policy version (= updates of the run).",
       [](const ProgressRow& r) { return double(r.stats.policy_version); }},
      {"policy_version", "policy_version", Metric::kGauge, Format::kInteger,
       "Newest published policy version (= updates of the run).",
       [](const ProgressRow& r) { return double(r.stats.policy_version); }},
      {"episodes", "episodes_total", Metric::kCounter, Format::kInteger,
       "Episodes finished in consumed segments.",
       [](const ProgressRow& r) { return double(r.stats.episodes); }},
      {"mean_return", "mean_return", Metric::kGauge, Format::kNumber,
       "Mean return of the last 100 finished episodes.",
       [](const ProgressRow& r) { return r.mean_return; }},
  };
}

std::vector<ProgressColumn> UpdateColumns() {
  return {
      {"policy_loss", "policy_loss", Metric::kGauge, Format::kNumber,
       "Policy (surrogate) loss of the last update.",
       [](const ProgressRow& r) { return r.stats.algorithm.policy_loss; }},
      {"value_loss", "value_loss", Metric::kGauge, Format::kNumber,
       "Critic loss of the last update.",
       [](const ProgressRow& r) { return r.stats.algorithm.value_loss; }},
      {"entropy", "policy_entropy", Metric::kGauge, Format::kNumber,
       "Mean entropy of the policy on the last batch.",
       [](const ProgressRow& r) { return r.stats.algorithm.entropy; }},
      {"approx_kl", "approx_kl", Metric::kGauge, Format::kNumber,
       "Approximate KL divergence from the acting policy after the update.",
       [](const ProgressRow& r) { return r.stats.algorithm.approx_kl; }},
      {"clip_fraction", "clip_fraction", Metric::kGauge, Format::kNumber,
       "Share of samples whose ratio was clipped (PPO).",
       [](const ProgressRow& r) { return r.stats.algorithm.clip_fraction; }},
      {"explained_variance", "explained_variance", Metric::kGauge,
       Format::kNumber,
       "1 - Var(returns - values) / Var(returns) of the last batch.",
       [](const ProgressRow& r) { return r.stats.explained_variance; }},
      {"biased_fraction", "biased_fraction", Metric::kGauge, Format::kNumber,
       "Share of the last batch's samples using the biased estimate.",
       [](const ProgressRow& r) { return r.stats.biased_fraction; }},
      {"mean_abs_bias", "mean_abs_bias", Metric::kGauge, Format::kNumber,
       "Mean |biased - GAE| advantage over the last batch.",
       [](const ProgressRow& r) { return r.stats.mean_abs_bias; }},
  };
}

std::vector<ProgressColumn> DiscardedWorkColumns() {
  return {
      {"rejected_segments", "batch_rejected_segments_total", Metric::kCounter,
       Format::kInteger,
       "Segments the learner's stitcher refused or dropped as stale.",
       [](const ProgressRow& r) { return double(r.stats.rejected_segments); }},
      {"rolled_back_updates", "rolled_back_updates_total", Metric::kCounter,
       Format::kInteger,
       "Updates undone because they produced non-finite numbers.",
       [](const ProgressRow& r) {
         return double(r.stats.rolled_back_updates);
       }},
  };
}

// Who fed the batch: with an elastic pool of remote actors, the actors and
// env streams live when it was taken.
std::vector<ProgressColumn> FeederColumns() {
  return {
      {"batch_actors", "batch_actors", Metric::kGauge, Format::kInteger,
       "Actors whose rollouts made the last batch.",
       [](const ProgressRow& r) { return double(r.stats.batch_actors); }},
      {"batch_env_slots", "batch_env_slots", Metric::kGauge, Format::kInteger,
       "Env streams (actor, slot) whose rollouts made the last batch.",
       [](const ProgressRow& r) { return double(r.stats.batch_env_slots); }},
  };
}

std::vector<ProgressColumn> ExplorationColumns() {
  return {
      {"exploration_loss", "exploration_model_loss", Metric::kGauge,
       Format::kNumber,
       "Mean loss of the exploration model's fit in the last update (EX2).",
       [](const ProgressRow& r) { return r.stats.exploration.model_loss; }},
      {"exploration_accuracy", "exploration_model_accuracy", Metric::kGauge,
       Format::kNumber,
       "Mean share of pairs the exploration model told apart in its last "
       "fit (EX2's discriminator).",
       [](const ProgressRow& r) { return r.stats.exploration.model_accuracy; }},
      {"exploration_bonus", "exploration_mean_bonus", Metric::kGauge,
       Format::kNumber,
       "Mean exploration bonus of the last batch before centring and "
       "weighting (EX2: -log p(s)).",
       [](const ProgressRow& r) { return r.stats.exploration.mean_bonus; }},
      {"exploration_bonus_std", "exploration_bonus_std", Metric::kGauge,
       Format::kNumber,
       "Standard deviation of the exploration bonus over the last batch "
       "(before weighting): how much it tells the batch's states apart.",
       [](const ProgressRow& r) { return r.stats.exploration.bonus_std; }},
  };
}

// Empty in the rows without an evaluation; on the dashboard the newest
// evaluation's figures stay until the next.
double Evaluated(const ProgressRow& row, double EvaluationSummary::*field) {
  return row.evaluation.has_value() ? (*row.evaluation).*field
                                    : std::numeric_limits<double>::quiet_NaN();
}

std::vector<ProgressColumn> EvaluationColumns() {
  return {
      {"eval_version", "eval_policy_version", Metric::kGauge, Format::kNumber,
       "Policy version of the newest evaluation (--eval_every).",
       [](const ProgressRow& r) {
         return r.evaluation.has_value()
                    ? double(r.evaluation->version)
                    : std::numeric_limits<double>::quiet_NaN();
       }},
      {"eval_return", "eval_return", Metric::kGauge, Format::kNumber,
       "Mean return of the deterministic policy over the newest "
       "evaluation's episodes.",
       [](const ProgressRow& r) {
         return Evaluated(r, &EvaluationSummary::mean);
       }},
      {"eval_return_std", "eval_return_std", Metric::kGauge, Format::kNumber,
       "Standard deviation of the newest evaluation's episode returns.",
       [](const ProgressRow& r) {
         return Evaluated(r, &EvaluationSummary::std);
       }},
      {"eval_return_min", "eval_return_min", Metric::kGauge, Format::kNumber,
       "Lowest episode return of the newest evaluation.",
       [](const ProgressRow& r) {
         return Evaluated(r, &EvaluationSummary::min);
       }},
      {"eval_return_max", "eval_return_max", Metric::kGauge, Format::kNumber,
       "Highest episode return of the newest evaluation.",
       [](const ProgressRow& r) {
         return Evaluated(r, &EvaluationSummary::max);
       }},
      {"eval_length", "eval_episode_length", Metric::kGauge, Format::kNumber,
       "Mean episode length of the newest evaluation.",
       [](const ProgressRow& r) {
         return Evaluated(r, &EvaluationSummary::mean_length);
       }},
  };
}

// Last in the file: the only columns a rerun with the same seed and flags
// does not repeat.
std::vector<ProgressColumn> TimeColumns() {
  return {
      {"elapsed_s", "run_elapsed_seconds", Metric::kGauge,
       Format::kMilliseconds, "Wall time of the whole run, across resumes.",
       [](const ProgressRow& r) { return r.elapsed_seconds; }},
      {"sps", "steps_per_second", Metric::kGauge, Format::kTenths,
       "Environment steps consumed per second since the process started.",
       [](const ProgressRow& r) { return r.steps_per_second; }},
  };
}

}  // namespace

const std::vector<ProgressColumn>& ProgressColumns() {
  static const std::vector<ProgressColumn> columns = [] {
    std::vector<ProgressColumn> all;
    for (const std::vector<ProgressColumn>& group :
         {RunProgressColumns(), UpdateColumns(), DiscardedWorkColumns(),
          FeederColumns(), ExplorationColumns(), EvaluationColumns(),
          TimeColumns()}) {
      all.insert(all.end(), group.begin(), group.end());
    }
    return all;
  }();
  return columns;
}

std::string ProgressHeader() {
  std::vector<std::string> names;
  for (const ProgressColumn& column : ProgressColumns()) {
    names.push_back(column.name);
  }
  return absl::StrJoin(names, ",");
}

std::string FormatProgressRow(const ProgressRow& row) {
  std::vector<std::string> fields;
  for (const ProgressColumn& column : ProgressColumns()) {
    fields.push_back(FormatValue(column.format, column.value(row)));
  }
  return absl::StrJoin(fields, ",");
}

}  // namespace vantage
