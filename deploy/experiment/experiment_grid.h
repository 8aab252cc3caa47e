#ifndef VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_GRID_H_
#define VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_GRID_H_

// Experiment files (proto/experiment.proto) and the grid of runs they
// expand into: one cell per combination of axis values and seed, each a
// run configuration resolved and checked before anything runs, each with
// its run directory EXP_DIR/<env>/<group>/seed-<seed>.

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "proto/experiment.pb.h"

namespace vantage {

// (flag name, value as on a command line), in the order they are set.
using FlagSettings = std::vector<std::pair<std::string, std::string>>;

// How the run flags are resolved, from the command line's own code (the
// cells are validated exactly as `vantage train` would validate them).
struct RunSettingsSchema {
  // The flags a setting may name.
  std::vector<std::string> flags;
  // `base` with `settings` on top, resolved and checked; errors name the
  // flag.
  std::function<absl::StatusOr<pb::RunConfig>(const pb::RunConfig& base,
                                              const FlagSettings& settings)>
      resolve;
};

struct ExpandOptions {
  std::string file;  // where the experiment came from (messages, records)
  // Every cell's steps are multiplied by this (rounded, at least 1): a
  // reduced version of the experiment. Must be > 0.
  double budget = 1.0;
  // If not empty, these seeds instead of the file's.
  std::vector<uint64_t> seeds;
};

// Parses an experiment file (JSON; unknown keys and wrong types are
// errors); messages start with the file's name.
absl::StatusOr<pb::Experiment> ReadExperimentFile(const std::string& path);
absl::StatusOr<pb::Experiment> ParseExperimentJson(const std::string& json,
                                                   const std::string& name);

// The experiment's cells, in order: axes, then variants, then seeds. Every
// rule broken is an InvalidArgument error naming the experiment field
// ("axes[1].values[0]: ...") or the cell and where its settings came from.
absl::StatusOr<pb::ExpandedExperiment> ExpandExperiment(
    const pb::Experiment& experiment, const ExpandOptions& options,
    const RunSettingsSchema& schema);

// The name of a cell's group: "<estimator>-rho<rho>-E<k1-k2-..>" ("gae"
// for the unbiased baseline), then "-<flag>_<value>" for each of `extra`
// (settings other than env, seed, estimator, rho and ensemble, and
// other than those an axis point sets together with the env), with
// characters unsafe in a path replaced.
std::string GroupName(const pb::RunConfig& resolved, const FlagSettings& extra);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_GRID_H_
