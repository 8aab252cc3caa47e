#ifndef VANTAGE_COMMON_ENV_FRAME_STACK_H_
#define VANTAGE_COMMON_ENV_FRAME_STACK_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/environment_wrapper.h"

namespace vantage {

// The most observations a FrameStack joins (DQN's Atari setup uses 4).
inline constexpr int64_t kMaxFrameStack = 16;

// The spec of `spec`'s environment seen through a FrameStack of `frames`
// (>= 1; 1 is `spec` itself): observation_size times `frames`, images
// stacked along their channels ([frames * C, H, W]), the same name, actions
// and bounds.
EnvSpec StackedSpec(const EnvSpec& spec, int64_t frames);

// Observations that are the last `frames` ones of the inner environment,
// oldest first, so a network without memory sees motion (MinAtar's and the
// maze's frames show no velocities). A Reset repeats the first observation
// `frames` times. A failed Reset or Step leaves the history as it was.
class FrameStack : public EnvironmentWrapper {
 public:
  // `frames` in [2, kMaxFrameStack]; anything else is InvalidArgument.
  static absl::StatusOr<std::unique_ptr<Environment>> Wrap(
      std::unique_ptr<Environment> inner, int64_t frames);

  const EnvSpec& spec() const override { return spec_; }
  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override;
  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override;
  // The history around the inner state.
  absl::StatusOr<std::string> SaveState() const override;
  absl::Status RestoreState(absl::string_view state) override;

  int64_t frames() const { return frames_; }

 private:
  FrameStack(std::unique_ptr<Environment> inner, int64_t frames);

  // Drops the oldest observation and appends latest_.
  void Push();
  void Write(absl::Span<double> observation) const;

  int64_t frames_;
  EnvSpec spec_;
  // The last `frames_` inner observations, oldest first, back to back.
  std::vector<double> history_;
  // Where the inner environment writes, so a failure changes no history.
  std::vector<double> latest_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ENV_FRAME_STACK_H_
