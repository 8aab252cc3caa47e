#include "actor/envs/choice/lit_buttons.h"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/util/split_mix.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "lit_buttons";
constexpr uint32_t kStateVersion = 1;

struct LitButtonsTask {
  int64_t buttons = 32;
  int64_t lit = 3;
  int64_t steps = 16;
  bool masked = true;
  bool dict = false;
};

std::vector<EnvOption> Options(LitButtonsTask& task) {
  return {{"buttons", "buttons on the panel (actions)", &task.buttons, 2},
          {"lit", "buttons lit (legal) at each step", &task.lit, 1},
          {"steps", "presses per episode", &task.steps, 1},
          {"masked",
           "action masks allow the lit buttons only (false: an unlit press "
           "costs 1)",
           &task.masked},
          {"dict",
           "the observation as a Dict of its two halves, \"lit\" and "
           "\"values\"",
           &task.dict}};
}

class LitButtons final : public Environment {
 public:
  LitButtons(const LitButtonsTask& task, std::string name)
      : task_(task), values_(task.buttons) {
    spec_.name = std::move(name);
    spec_.observation_size = 2 * task.buttons;
    if (task.dict) {
      spec_.observation_keys = {{"lit", task.buttons, {}, 0},
                                {"values", task.buttons, {}, 0}};
    }
    spec_.discrete = true;
    spec_.action_size = task.buttons;
    spec_.action_masks = task.masked;
    spec_.max_episode_steps = task.steps;
    // No physics: a press every tenth of a second.
    spec_.control_dt = 0.1;
  }

  const EnvSpec& spec() const override { return spec_; }

  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override {
    if (absl::Status status = CheckObservationBuffer(spec_, observation);
        !status.ok()) {
      return status;
    }
    seed_ = seed;
    step_ = 0;
    Draw();
    Observe(observation);
    return absl::OkStatus();
  }

  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override {
    if (absl::Status status =
            CheckStep(spec_, step_ >= task_.steps, action, observation);
        !status.ok()) {
      return status;
    }
    const int64_t button = static_cast<int64_t>(action[0]);
    StepResult result;
    if (values_[button] >= 0.0) {
      result.reward = values_[button];
    } else if (task_.masked) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name, ": button ", button, " is not lit (its mask is 0)"));
    } else {
      result.reward = -1.0;
    }
    ++step_;
    result.terminated = step_ == task_.steps;
    Draw();
    Observe(observation);
    return result;
  }

  absl::Status ActionMask(absl::Span<uint8_t> mask) const override {
    if (!task_.masked) return Environment::ActionMask(mask);
    if (mask.size() != values_.size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec_.name, ": the mask holds ", values_.size(), " entries"));
    }
    for (size_t i = 0; i < values_.size(); ++i) mask[i] = values_[i] >= 0.0;
    return absl::OkStatus();
  }

  absl::StatusOr<std::string> SaveState() const override {
    StateWriter writer(kStateKind, kStateVersion);
    writer.PutBytes(spec_.name);
    writer.PutI64(static_cast<int64_t>(seed_));
    writer.PutI64(step_);
    return std::move(writer).Finish();
  }

  absl::Status RestoreState(absl::string_view state) override {
    StateReader reader(state, kStateKind, kStateVersion, spec_.name);
    reader.ExpectEqual("the task", reader.GetBytes("name"), spec_.name);
    const uint64_t seed = static_cast<uint64_t>(reader.GetI64("seed"));
    const int64_t step = reader.GetI64("step");
    reader.Check(step >= 0 && step <= task_.steps,
                 absl::StrCat("step ", step, " out of range"));
    if (absl::Status status = reader.Finish(); !status.ok()) return status;
    seed_ = seed;
    step_ = step;
    Draw();
    return absl::OkStatus();
  }

 private:
  // The lit buttons and their values at this step, from the episode's seed
  // alone; -1 marks an unlit button.
  void Draw() {
    std::mt19937_64 rng(SplitMixSeed(seed_, static_cast<uint64_t>(step_)));
    std::vector<int64_t> order(task_.buttons);
    std::iota(order.begin(), order.end(), 0);
    std::fill(values_.begin(), values_.end(), -1.0);
    std::uniform_real_distribution<double> value(0.0, 1.0);
    for (int64_t i = 0; i < task_.lit; ++i) {
      std::swap(order[i], order[i + rng() % (task_.buttons - i)]);
      values_[order[i]] = value(rng);
    }
  }

  void Observe(absl::Span<double> observation) const {
    const int64_t n = task_.buttons;
    for (int64_t i = 0; i < n; ++i) {
      const bool lit = values_[i] >= 0.0;
      observation[i] = lit ? 1.0 : 0.0;
      observation[n + i] = lit ? values_[i] : 0.0;
    }
  }

  const LitButtonsTask task_;
  EnvSpec spec_;
  uint64_t seed_ = 0;
  int64_t step_ = 0;
  std::vector<double> values_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeLitButtons(
    const EnvName& name) {
  LitButtonsTask task;
  if (absl::Status status =
          ApplyEnvOptions(name.task, Options(task), name.options);
      !status.ok()) {
    return status;
  }
  if (task.lit > task.buttons) {
    return absl::InvalidArgumentError(absl::StrCat(
        name.task, ": lit=", task.lit, " exceeds buttons=", task.buttons,
        " (at most every button can be lit)"));
  }
  return std::make_unique<LitButtons>(task, name.Canonical());
}

std::vector<EnvOptionInfo> LitButtonsOptions() {
  LitButtonsTask task;
  return Describe(Options(task));
}

}  // namespace vantage
