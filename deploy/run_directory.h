#ifndef VANTAGE_DEPLOY_RUN_DIRECTORY_H_
#define VANTAGE_DEPLOY_RUN_DIRECTORY_H_

// A training run's directory:
//   config.json     the resolved run config (`vantage train --config` and
//                   --resume read it back)
//   progress.csv    one row per update (columns: kProgressColumns)
//   checkpoints/    checkpoint-<version>.pt, the newest few kept

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "learner/learner_core.h"

namespace vantage {

// Every column but the last two (wall-clock) repeats exactly for the same
// seed and flags.
inline constexpr char kProgressColumns[] =
    "env_steps,updates,policy_version,episodes,mean_return,policy_loss,"
    "value_loss,entropy,approx_kl,clip_fraction,explained_variance,"
    "biased_fraction,mean_abs_bias,rejected_segments,rolled_back_updates,"
    "elapsed_s,sps";

struct ProgressRow {
  UpdateStats stats;
  double mean_return = 0.0;       // last 100 episodes; NaN: none finished yet
  double elapsed_seconds = 0.0;   // of the whole run, across resumes
  double steps_per_second = 0.0;  // since this process started
};

// The CSV line (no newline); NaN values are empty fields.
std::string FormatProgressRow(const ProgressRow& row);

class RunDirectory {
 public:
  // Starts a new run in `path` (created if missing). A directory that
  // already holds a run is refused: continue it with --resume.
  static absl::StatusOr<RunDirectory> Create(const std::string& path,
                                             const std::string& config_json);
  // AlreadyExists if `path` holds a run (what Create refuses); creates
  // nothing.
  static absl::Status CheckFree(const std::string& path);
  // An existing run, to resume.
  static absl::StatusOr<RunDirectory> Open(const std::string& path);

  const std::string& path() const { return path_; }
  std::string config_path() const;
  std::string checkpoint_directory() const;

  // Drops the rows after update `updates` (written after the checkpoint a
  // resumed run continues from), atomically.
  absl::Status TruncateProgress(int64_t updates) const;
  absl::Status AppendProgress(const ProgressRow& row) const;

 private:
  explicit RunDirectory(std::string path) : path_(std::move(path)) {}
  std::string progress_path() const;

  std::string path_;
};

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_DIRECTORY_H_
