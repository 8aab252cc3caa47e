#ifndef VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_DIRECTORY_H_
#define VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_DIRECTORY_H_

// An experiment's directory:
//   experiment.json   the expanded grid (pb::ExpandedExperiment as JSON)
//   base.json         the base run config every cell's flags go on top of
//   <env>/<group>/seed-<seed>/   one run directory per cell (`vantage
//                     train --run_dir`), with train.log beside its files

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "proto/experiment.pb.h"

namespace vantage {

// Where a cell's run stands.
enum class CellState {
  kNew,           // nothing there yet
  kResumable,     // started, unfinished, with a checkpoint to resume from
  kNoCheckpoint,  // started and stopped before its first checkpoint
  kFinished,      // progress.csv reached the cell's steps
};

struct CellStatus {
  CellState state = CellState::kNew;
  int64_t env_steps = 0;  // of progress.csv's last row
};

class ExperimentDirectory {
 public:
  explicit ExperimentDirectory(std::string path) : path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  std::string RunDir(const pb::ExperimentCell& cell) const;
  std::string LogPath(const pb::ExperimentCell& cell) const;
  std::string BaseConfigPath() const;
  std::string ExperimentPath() const;

  // Checks that every cell's run directory that already holds a run was
  // made with the cell's configuration (else FailedPrecondition naming the
  // directory and the first setting that differs: the experiment file or
  // --budget changed, so its results would not be this grid's).
  absl::Status CheckRuns(const pb::ExpandedExperiment& experiment) const;
  // The experiment's cells added to those experiment.json already records
  // (a run of other seeds or cells, or with --only, extends the record):
  // FailedPrecondition if the record was made at another budget or holds
  // one of the cells with other settings.
  absl::StatusOr<pb::ExpandedExperiment> Merged(
      const pb::ExpandedExperiment& experiment) const;
  // CheckRuns, then creates the directory and writes experiment.json (the
  // merged record) and base.json.
  absl::Status Prepare(const pb::ExpandedExperiment& experiment,
                       const pb::RunConfig& base) const;

  CellStatus Inspect(const pb::ExperimentCell& cell) const;

  // Removes a run stopped before its first checkpoint (config.json,
  // progress.csv, checkpoints/, launch/) so it can start again; its log
  // stays.
  absl::Status ClearRun(const pb::ExperimentCell& cell) const;

 private:
  std::string path_;
};

// The env_steps of progress.csv's last row in `run_dir` (0 if none).
int64_t LastProgressSteps(const std::string& run_dir);
// The last non-empty line of a cell's log ("" if none), for failure reports.
std::string LastLogLine(const std::string& log_path);

// experiment.json's content.
std::string ExpandedExperimentToJson(const pb::ExpandedExperiment& experiment);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_DIRECTORY_H_
