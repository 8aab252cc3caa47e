#ifndef VANTAGE_LEARNER_RUN_RUN_RESUME_H_
#define VANTAGE_LEARNER_RUN_RUN_RESUME_H_

// Continuing a recorded run from its newest checkpoint that loads; the
// counterpart of the checkpoints RunRecorder writes.

#include <memory>
#include <string>

#include "absl/functional/function_ref.h"
#include "absl/status/statusor.h"
#include "learner/checkpoint/checkpoint.h"
#include "learner/learner_core.h"
#include "learner/run/run_directory.h"

namespace vantage {

struct ResumePoint {
  std::unique_ptr<LearnerCore> learner;
  CheckpointExtras extras;
  double elapsed_seconds = 0.0;  // of the run when the checkpoint was written
};

// Turns one checkpoint (its path and already-read extras) into a learner,
// restoring whatever else the caller keeps in the extras, or says why not.
using CheckpointLoader =
    absl::FunctionRef<absl::StatusOr<std::unique_ptr<LearnerCore>>(
        const std::string& path, const CheckpointExtras& extras)>;

// Tries the run's checkpoints newest first; one that does not load is
// reported on stderr and the one before it tried. NotFound without any
// checkpoint, DataLoss (listing every reason) when none loads. With
// `truncate_progress` the run's progress rows after the checkpoint are
// dropped, so the continued run appends where the checkpoint left off.
absl::StatusOr<ResumePoint> ResumeFromNewestCheckpoint(RunDirectory& run,
                                                       bool truncate_progress,
                                                       CheckpointLoader load);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_RUN_RESUME_H_
