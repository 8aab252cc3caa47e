#ifndef VANTAGE_COMMON_ENV_ENVIRONMENT_WRAPPER_H_
#define VANTAGE_COMMON_ENV_ENVIRONMENT_WRAPPER_H_

#include <memory>
#include <string>
#include <utility>

#include "common/env/environment.h"

namespace vantage {

// An environment around another one (a time limit, a frame stack): every
// call goes to the inner environment unless the wrapper overrides it, so a
// wrapper states only what it changes.
class EnvironmentWrapper : public Environment {
 public:
  explicit EnvironmentWrapper(std::unique_ptr<Environment> inner)
      : inner_(std::move(inner)) {}

  const EnvSpec& spec() const override { return inner_->spec(); }
  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override {
    return inner_->Reset(seed, observation);
  }
  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override {
    return inner_->Step(action, observation);
  }
  absl::StatusOr<std::string> SaveState() const override {
    return inner_->SaveState();
  }
  absl::Status RestoreState(absl::string_view state) override {
    return inner_->RestoreState(state);
  }
  absl::Status ActionMask(absl::Span<uint8_t> mask) const override {
    return inner_->ActionMask(mask);
  }
  absl::StatusOr<Frame> Render(int width, int height) override {
    return inner_->Render(width, height);
  }

  // The wrapped environment (benchmarks reach the physics through it).
  const Environment& inner() const { return *inner_; }

 protected:
  Environment& mutable_inner() { return *inner_; }

 private:
  std::unique_ptr<Environment> inner_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ENV_ENVIRONMENT_WRAPPER_H_
