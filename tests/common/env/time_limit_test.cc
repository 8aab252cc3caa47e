#include "common/env/time_limit.h"

#include <memory>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

// Renders a solid colour, or (`can_render` false) keeps the default.
class Painted : public Environment {
 public:
  explicit Painted(bool can_render) : can_render_(can_render) {
    spec_.name = "Painted";
    spec_.observation_size = 1;
    spec_.action_size = 1;
    spec_.action_low = {-1.0};
    spec_.action_high = {1.0};
  }
  const EnvSpec& spec() const override { return spec_; }
  absl::Status Reset(uint64_t, absl::Span<double> observation) override {
    observation[0] = 0.0;
    return absl::OkStatus();
  }
  absl::StatusOr<StepResult> Step(absl::Span<const double>,
                                  absl::Span<double>) override {
    return StepResult{};
  }
  absl::StatusOr<Frame> Render(int width, int height) override {
    if (!can_render_) return Environment::Render(width, height);
    Frame frame;
    frame.width = width;
    frame.height = height;
    frame.rgb.assign(3 * width * height, 7);
    return frame;
  }

 private:
  EnvSpec spec_;
  bool can_render_;
};

TEST(TimeLimitRenderTest, ForwardsRenderToTheWrappedEnvironment) {
  TimeLimit limited(std::make_unique<Painted>(true));
  absl::StatusOr<Frame> frame = limited.Render(4, 2);
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->width, 4);
  EXPECT_EQ(frame->rgb.size(), 24u);
  EXPECT_EQ(frame->rgb[0], 7);
}

TEST(TimeLimitRenderTest, AnEnvironmentWithoutRenderSaysSo) {
  TimeLimit limited(std::make_unique<Painted>(false));
  absl::StatusOr<Frame> frame = limited.Render(4, 2);
  EXPECT_TRUE(absl::IsUnimplemented(frame.status()));
  EXPECT_THAT(frame.status().message(),
              ::testing::HasSubstr("Painted: this environment cannot render"));
}

}  // namespace
}  // namespace vantage
