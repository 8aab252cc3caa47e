#ifndef VANTAGE_LEARNER_CHECKPOINT_H_
#define VANTAGE_LEARNER_CHECKPOINT_H_

// Checkpoint files: the learner's whole state plus named byte strings the
// caller adds (the run's resolved config, the local actor's state, ...).
// A checkpoint is written to a temporary file, flushed to disk and renamed
// into place, so a crash never leaves a half-written checkpoint under a
// checkpoint's name.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "learner/learner_core.h"

namespace vantage {

using CheckpointExtras = std::map<std::string, std::string>;

// `directory`/checkpoint-<version, 8 digits>.pt
std::string CheckpointPath(const std::string& directory, int64_t version);

absl::Status WriteCheckpoint(const std::string& path,
                             const LearnerCore& learner,
                             const CheckpointExtras& extras);

// The extras alone (e.g. to learn the config a learner needs).
absl::StatusOr<CheckpointExtras> ReadCheckpointExtras(const std::string& path);

// A learner for `config` with the checkpoint's state (one of `replicas`,
// which all read the same checkpoint).
absl::StatusOr<std::unique_ptr<LearnerCore>> ReadCheckpoint(
    const std::string& path, const LearnerConfig& config,
    std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());

// The checkpoint files in `directory`, oldest (lowest version) first.
std::vector<std::string> ListCheckpoints(const std::string& directory);

// Deletes all but the newest `keep` checkpoints.
absl::Status PruneCheckpoints(const std::string& directory, int keep);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_CHECKPOINT_H_
