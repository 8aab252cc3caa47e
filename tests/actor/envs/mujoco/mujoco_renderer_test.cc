#include "actor/envs/mujoco/mujoco_renderer.h"

#include <cstring>
#include <memory>
#include <vector>

#include "actor/envs/env_registry.h"
#include "actor/envs/mujoco/mujoco_model.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

// A ball on a slide over a floor, with a camera looking at it.
constexpr char kSlideXml[] = R"xml(
<mujoco>
  <worldbody>
    <light pos="0 0 4"/>
    <camera name="side" pos="0 -4 1" xyaxes="1 0 0 0 0.125 1"/>
    <geom type="plane" size="5 5 0.1" rgba="0.3 0.5 0.3 1"/>
    <body name="ball" pos="0 0 0.5">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom type="sphere" size="0.3" rgba="1 0 0 1"/>
    </body>
  </worldbody>
</mujoco>
)xml";

class MujocoRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    absl::StatusOr<LoadedModel> loaded = LoadModelAndData("slide", kSlideXml);
    ASSERT_TRUE(loaded.ok()) << loaded.status();
    model_ = std::move(loaded->model);
    data_ = std::move(loaded->data);
    mj_forward(model_.get(), data_.get());
  }

  MjModelPtr model_;
  MjDataPtr data_;
};

bool IsUniform(const Frame& frame) {
  for (size_t i = 3; i < frame.rgb.size(); i += 3) {
    if (std::memcmp(frame.rgb.data(), frame.rgb.data() + i, 3) != 0) {
      return false;
    }
  }
  return true;
}

TEST_F(MujocoRendererTest, DrawsTheModelAndFollowsItsMotion) {
  auto renderer = MujocoRenderer::Create(model_.get(), 96, 64);
  ASSERT_TRUE(renderer.ok()) << renderer.status();
  absl::StatusOr<Frame> before = (*renderer)->Render(data_.get(), {});
  ASSERT_TRUE(before.ok()) << before.status();
  EXPECT_EQ(before->width, 96);
  EXPECT_EQ(before->height, 64);
  ASSERT_EQ(before->rgb.size(), 96u * 64u * 3u);
  EXPECT_FALSE(IsUniform(*before));
  // The fixed camera sees the red ball in the middle of the frame.
  const uint8_t* centre = before->rgb.data() + 3 * (32 * 96 + 48);
  EXPECT_GT(centre[0], 2 * centre[1])
      << int(centre[0]) << " " << int(centre[1]);

  data_->qpos[0] = 1.0;
  mj_forward(model_.get(), data_.get());
  absl::StatusOr<Frame> after = (*renderer)->Render(data_.get(), {});
  ASSERT_TRUE(after.ok());
  EXPECT_NE(before->rgb, after->rgb);
}

TEST_F(MujocoRendererTest, LeavesTheModelAndDataAlone) {
  const int offwidth = model_->vis.global.offwidth;
  std::vector<char> buffer(static_cast<char*>(data_->buffer),
                           static_cast<char*>(data_->buffer) + data_->nbuffer);
  // Larger than the model's offscreen buffer (640x480 by default).
  auto renderer = MujocoRenderer::Create(model_.get(), 800, 600);
  ASSERT_TRUE(renderer.ok()) << renderer.status();
  MujocoView view;
  view.track_body = 1;
  absl::StatusOr<Frame> frame = (*renderer)->Render(data_.get(), view);
  ASSERT_TRUE(frame.ok()) << frame.status();
  EXPECT_EQ(frame->rgb.size(), 800u * 600u * 3u);
  EXPECT_FALSE(IsUniform(*frame));
  EXPECT_EQ(model_->vis.global.offwidth, offwidth);
  EXPECT_EQ(std::memcmp(buffer.data(), data_->buffer, buffer.size()), 0);
}

TEST_F(MujocoRendererTest, TwoRenderersTakeTurns) {
  auto first = MujocoRenderer::Create(model_.get(), 64, 48);
  auto second = MujocoRenderer::Create(model_.get(), 32, 32);
  ASSERT_TRUE(first.ok() && second.ok());
  absl::StatusOr<Frame> a = (*first)->Render(data_.get(), {});
  absl::StatusOr<Frame> b = (*second)->Render(data_.get(), {});
  absl::StatusOr<Frame> again = (*first)->Render(data_.get(), {});
  ASSERT_TRUE(a.ok() && b.ok() && again.ok());
  EXPECT_EQ(b->rgb.size(), 32u * 32u * 3u);
  EXPECT_EQ(a->rgb, again->rgb);
}

// Rendering every step changes nothing the environment produces.
TEST(MujocoEnvRenderTest, HalfCheetahEpisodesAreTheSameWhenRendered) {
  auto plain = MakeEnvironment("HalfCheetah");
  auto rendered = MakeEnvironment("HalfCheetah");
  ASSERT_TRUE(plain.ok() && rendered.ok());
  EXPECT_TRUE(absl::IsFailedPrecondition((*rendered)->Render(64, 48).status()));
  std::vector<double> a(17), b(17), action(6);
  ASSERT_TRUE((*plain)->Reset(3, absl::MakeSpan(a)).ok());
  ASSERT_TRUE((*rendered)->Reset(3, absl::MakeSpan(b)).ok());
  std::vector<uint8_t> first_frame;
  for (int t = 0; t < 30; ++t) {
    absl::StatusOr<Frame> frame = (*rendered)->Render(64, 48);
    ASSERT_TRUE(frame.ok()) << frame.status();
    if (t == 0) first_frame = frame->rgb;
    for (int i = 0; i < 6; ++i) action[i] = ((t + i) % 3 - 1) * 0.9;
    auto step_a = (*plain)->Step(action, absl::MakeSpan(a));
    auto step_b = (*rendered)->Step(action, absl::MakeSpan(b));
    ASSERT_TRUE(step_a.ok() && step_b.ok());
    ASSERT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0)
        << "step " << t;
    ASSERT_EQ(step_a->reward, step_b->reward);
  }
  absl::StatusOr<Frame> last = (*rendered)->Render(64, 48);
  ASSERT_TRUE(last.ok());
  EXPECT_NE(last->rgb, first_frame);
}

}  // namespace
}  // namespace vantage
