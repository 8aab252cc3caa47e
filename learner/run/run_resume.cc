#include "learner/run/run_resume.h"

#include <cstdio>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "learner/run/run_recorder.h"

namespace vantage {

absl::StatusOr<ResumePoint> ResumeFromNewestCheckpoint(RunDirectory& run,
                                                       bool truncate_progress,
                                                       CheckpointLoader load) {
  const std::vector<std::string> paths =
      ListCheckpoints(run.checkpoint_directory());
  if (paths.empty()) {
    return absl::NotFoundError(
        absl::StrCat(run.path(), " has no checkpoint to resume from"));
  }
  std::string problems;
  for (auto path = paths.rbegin(); path != paths.rend(); ++path) {
    absl::StatusOr<CheckpointExtras> extras = ReadCheckpointExtras(*path);
    absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
        extras.ok()
            ? load(*path, *extras)
            : absl::StatusOr<std::unique_ptr<LearnerCore>>(extras.status());
    if (learner.ok()) {
      ResumePoint resumed;
      resumed.learner = *std::move(learner);
      resumed.extras = *std::move(extras);
      if (auto elapsed = resumed.extras.find(kCheckpointElapsed);
          elapsed != resumed.extras.end()) {
        (void)absl::SimpleAtod(elapsed->second, &resumed.elapsed_seconds);
      }
      if (absl::Status status =
              truncate_progress
                  ? run.TruncateProgress(resumed.learner->policy_version())
                  : absl::OkStatus();
          !status.ok()) {
        return status;
      }
      return resumed;
    }
    std::fprintf(stderr, "vantage: skipping checkpoint %s: %s\n", path->c_str(),
                 std::string(learner.status().message()).c_str());
    absl::StrAppend(&problems, problems.empty() ? "" : "; ",
                    learner.status().message());
  }
  return absl::DataLossError(absl::StrCat(
      "no checkpoint in ", run.checkpoint_directory(), " loads: ", problems));
}

}  // namespace vantage
