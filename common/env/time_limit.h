#ifndef VANTAGE_COMMON_ENV_TIME_LIMIT_H_
#define VANTAGE_COMMON_ENV_TIME_LIMIT_H_

#include <cstdint>
#include <memory>
#include <string>

#include "common/env/environment_wrapper.h"

namespace vantage {

// Truncates episodes after spec().max_episode_steps steps (never marking
// them terminated), and refuses to step an episode that has not been reset
// or has already ended.
class TimeLimit : public EnvironmentWrapper {
 public:
  explicit TimeLimit(std::unique_ptr<Environment> inner);

  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override;
  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override;
  // The step count and whether an episode runs, around the inner state.
  absl::StatusOr<std::string> SaveState() const override;
  absl::Status RestoreState(absl::string_view state) override;

  int64_t elapsed_steps() const { return elapsed_steps_; }

 private:
  int64_t elapsed_steps_ = 0;
  bool running_ = false;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ENV_TIME_LIMIT_H_
