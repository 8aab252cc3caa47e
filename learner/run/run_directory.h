#ifndef VANTAGE_LEARNER_RUN_RUN_DIRECTORY_H_
#define VANTAGE_LEARNER_RUN_RUN_DIRECTORY_H_

// A training run's directory:
//   config.json     the resolved run config (`vantage train --config` and
//                   --resume read it back)
//   progress.csv    one row per update (columns: ProgressColumns())
//   checkpoints/    checkpoint-<version>.pt, the newest few kept

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "learner/run/progress_columns.h"

namespace vantage {

// Writes `text` to `path` through a temporary file renamed over it, so a
// reader never sees half of it.
absl::Status WriteFileAtomically(const std::string& path,
                                 const std::string& text);

// A whole row of progress.csv with the two columns that place it.
struct ProgressLine {
  int64_t env_steps = 0;
  int64_t updates = 0;
  std::string text;
};

// progress.csv's rows in `run_dir`, up to the first that is not whole (as
// many fields as the header, the first two numbers: the torn last line of a
// killed run is not); none if there is no file.
std::vector<ProgressLine> ReadProgressLines(const std::string& run_dir);

class RunDirectory {
 public:
  // Starts a new run in `path` (created if missing). A directory that
  // already holds a run is refused: continue it with --resume.
  static absl::StatusOr<RunDirectory> Create(const std::string& path,
                                             const std::string& config_json);
  // AlreadyExists if `path` holds a run (what Create refuses); creates
  // nothing.
  static absl::Status CheckFree(const std::string& path);
  // Removes what a run writes into `path` (config.json, progress.csv,
  // checkpoints/, the launcher's launch/), so that a run that never
  // checkpointed can start over there; other files (a log) stay.
  static absl::Status Clear(const std::string& path);
  // An existing run, to resume.
  static absl::StatusOr<RunDirectory> Open(const std::string& path);

  const std::string& path() const { return path_; }
  std::string config_path() const;
  std::string checkpoint_directory() const;

  // Adds this machine's CPU model to machine.json ({"cpu_models": [...]},
  // every model that ran a part of the run, in order), so that results
  // of different machines are not compared unawares.
  absl::Status RecordMachine() const;
  std::string machine_path() const;

  // Drops the rows after update `updates` (written after the checkpoint a
  // resumed run continues from), atomically.
  absl::Status TruncateProgress(int64_t updates) const;
  absl::Status AppendProgress(const ProgressRow& row) const;

 private:
  friend std::vector<ProgressLine> ReadProgressLines(const std::string&);
  explicit RunDirectory(std::string path) : path_(std::move(path)) {}
  std::string progress_path() const;

  std::string path_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_RUN_DIRECTORY_H_
