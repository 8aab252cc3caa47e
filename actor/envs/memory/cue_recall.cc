#include "actor/envs/memory/cue_recall.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/util/split_mix.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "cue_recall";
constexpr uint32_t kStateVersion = 1;

struct CueRecallTask {
  int64_t cues = 4;
  int64_t delay = 10;
};

std::vector<EnvOption> Options(CueRecallTask& task) {
  return {
      {"cues", "cues to tell apart (actions)", &task.cues, 2},
      {"delay", "blank steps between the cue and the recall", &task.delay, 0}};
}

class CueRecall final : public Environment {
 public:
  CueRecall(const CueRecallTask& task, std::string name) : task_(task) {
    spec_.name = std::move(name);
    spec_.observation_size = task.cues + 2;
    spec_.discrete = true;
    spec_.action_size = task.cues;
    // The cue, the delay and the recall.
    spec_.max_episode_steps = task.delay + 2;
    // No physics: a step is a moment of a video played at 10 per second.
    spec_.control_dt = 0.1;
  }

  const EnvSpec& spec() const override { return spec_; }

  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override {
    if (observation.size() != static_cast<size_t>(spec_.observation_size)) {
      return absl::InvalidArgumentError(
          absl::StrCat(spec_.name, ": the observation holds ",
                       spec_.observation_size, " values"));
    }
    cue_ = static_cast<int64_t>(SplitMixSeed(seed, 0) %
                                static_cast<uint64_t>(task_.cues));
    step_ = 0;
    Observe(observation);
    return absl::OkStatus();
  }

  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override {
    if (absl::Status status = CheckAction(spec_, action); !status.ok()) {
      return status;
    }
    if (step_ > task_.delay) {
      return absl::FailedPreconditionError(
          absl::StrCat(spec_.name, ": the episode ended; reset first"));
    }
    StepResult result;
    if (step_ == task_.delay) {  // this step answered the recall
      result.reward = static_cast<int64_t>(action[0]) == cue_ ? 1.0 : 0.0;
      result.terminated = true;
    }
    ++step_;
    Observe(observation);
    return result;
  }

  absl::StatusOr<std::string> SaveState() const override {
    StateWriter writer(kStateKind, kStateVersion);
    writer.PutI64(task_.cues);
    writer.PutI64(task_.delay);
    writer.PutI64(cue_);
    writer.PutI64(step_);
    return std::move(writer).Finish();
  }

  absl::Status RestoreState(absl::string_view state) override {
    StateReader reader(state, kStateKind, kStateVersion, spec_.name);
    reader.ExpectEqual("cues", reader.GetI64("cues"), task_.cues);
    reader.ExpectEqual("delay", reader.GetI64("delay"), task_.delay);
    const int64_t cue = reader.GetI64("cue");
    const int64_t step = reader.GetI64("step");
    reader.Check(
        cue >= 0 && cue < task_.cues && step >= 0 && step <= task_.delay + 1,
        "cue or step out of range");
    if (absl::Status status = reader.Finish(); !status.ok()) return status;
    cue_ = cue;
    step_ = step;
    return absl::OkStatus();
  }

 private:
  // Step 0 shows the cue; step delay (after `delay` blank ones) asks.
  void Observe(absl::Span<double> observation) const {
    std::fill(observation.begin(), observation.end(), 0.0);
    if (step_ == 0) {
      observation[cue_] = 1.0;
      observation[task_.cues] = 1.0;
    }
    if (step_ == task_.delay) observation[task_.cues + 1] = 1.0;
  }

  const CueRecallTask task_;
  EnvSpec spec_;
  int64_t cue_ = 0;
  int64_t step_ = 0;
};

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeCueRecall(
    const EnvName& name) {
  CueRecallTask task;
  if (absl::Status status =
          ApplyEnvOptions(name.task, Options(task), name.options);
      !status.ok()) {
    return status;
  }
  return std::make_unique<CueRecall>(task, name.Canonical());
}

std::vector<EnvOptionInfo> CueRecallOptions() {
  CueRecallTask task;
  return Describe(Options(task));
}

}  // namespace vantage
