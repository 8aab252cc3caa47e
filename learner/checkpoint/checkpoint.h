#ifndef VANTAGE_LEARNER_CHECKPOINT_CHECKPOINT_H_
#define VANTAGE_LEARNER_CHECKPOINT_CHECKPOINT_H_

// Checkpoint files: the learner's whole state plus named byte strings the
// caller adds (the run's resolved config, the local actor's state, ...).
// A checkpoint is written to a temporary file, flushed to disk and renamed
// into place, so a crash never leaves a half-written checkpoint under a
// checkpoint's name.

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "learner/checkpoint/checkpoint_files.h"
#include "learner/learner_core.h"

namespace vantage {

absl::Status WriteCheckpoint(const std::string& path,
                             const LearnerCore& learner,
                             const CheckpointExtras& extras);

// A learner for `config` with the checkpoint's state (one of `replicas`,
// which all read the same checkpoint).
absl::StatusOr<std::unique_ptr<LearnerCore>> ReadCheckpoint(
    const std::string& path, const LearnerConfig& config,
    std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());

}  // namespace vantage

#endif  // VANTAGE_LEARNER_CHECKPOINT_CHECKPOINT_H_
