#ifndef VANTAGE_LEARNER_CHECKPOINT_CHECKPOINT_FILES_H_
#define VANTAGE_LEARNER_CHECKPOINT_CHECKPOINT_FILES_H_

// A run's checkpoint files by name, and their extras, without the learner
// (learner/checkpoint/checkpoint.h writes and reads the learner's state).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace vantage {

// Named byte strings a checkpoint holds beside the learner's state (the
// run's resolved config, the local actor's state, ...).
using CheckpointExtras = std::map<std::string, std::string>;

// `directory`/checkpoint-<version, 8 digits>.pt
std::string CheckpointPath(const std::string& directory, int64_t version);

// The extras alone (e.g. to learn the config a learner needs).
absl::StatusOr<CheckpointExtras> ReadCheckpointExtras(const std::string& path);

// The checkpoint files in `directory`, oldest (lowest version) first.
std::vector<std::string> ListCheckpoints(const std::string& directory);

// Deletes all but the newest `keep` checkpoints.
absl::Status PruneCheckpoints(const std::string& directory, int keep);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_CHECKPOINT_CHECKPOINT_FILES_H_
