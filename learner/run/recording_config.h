#ifndef VANTAGE_LEARNER_RUN_RECORDING_CONFIG_H_
#define VANTAGE_LEARNER_RUN_RECORDING_CONFIG_H_

#include <string>

#include "absl/status/status.h"

namespace vantage {
namespace pb {
class RecordingSettings;
}  // namespace pb

// Where and how a run is recorded (see learner/run/run_directory.h):
// config.json with `config_json`, progress.csv, and a checkpoint every
// `checkpoint_every` updates and at the end, keeping the newest
// `keep_checkpoints`; no run directory: nothing is written.
struct RecordingConfig {
  std::string run_dir;
  std::string config_json;  // the resolved run config
  int checkpoint_every = 10;
  int keep_checkpoints = 3;
  // Continue the run in run_dir from its newest readable checkpoint (an
  // unreadable one is reported and the one before it used); the continued
  // run's progress equals an uninterrupted run's.
  bool resume = false;
  // False for the replicas of a data-parallel run other than rank 0: they
  // read run_dir's checkpoints to resume but write nothing there.
  bool record = true;

  // checkpoint_every and keep_checkpoints are >= 1 (the message names the
  // flag).
  absl::Status Validate() const;
};

// The run config's recording section with every absent setting given its
// default, checked (its table is in recording_config.cc).
absl::Status ResolveRecordingSettings(pb::RecordingSettings& settings);
// The settings of a resolved section over the defaults.
RecordingConfig RecordingConfigOf(const pb::RecordingSettings& settings);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_RECORDING_CONFIG_H_
