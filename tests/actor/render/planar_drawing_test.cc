#include "actor/render/planar_drawing.h"

#include <cmath>
#include <vector>

#include "actor/envs/env_registry.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

const uint8_t* Pixel(const Frame& frame, int x, int y) {
  return frame.rgb.data() + 3 * (y * frame.width + x);
}

// 100 x 100 pixels over 2 m: 50 pixels a metre, the centre (0, 1) at pixel
// (50, 50), the ground (z = 0) at row 100.
PlanarScene Standing(bool far_side) {
  PlanarScene scene;
  scene.centre_x = 0.0;
  scene.centre_z = 1.0;
  scene.view_height = 2.0;
  PlanarCapsule capsule;
  capsule.from_x = 0.0;
  capsule.from_z = 0.6;
  capsule.to_x = 0.0;
  capsule.to_z = 1.4;
  capsule.radius = 0.1;
  capsule.far_side = far_side;
  scene.capsules.push_back(capsule);
  return scene;
}

TEST(PlanarDrawingTest, SkyGroundAndCapsuleWhereTheyBelong) {
  PlanarScene scene = Standing(false);
  scene.centre_z = 0.8;  // ground at row 90
  absl::StatusOr<Frame> frame = DrawPlanarScene(scene, 100, 100);
  ASSERT_TRUE(frame.ok()) << frame.status();
  ASSERT_EQ(frame->rgb.size(), 100u * 100u * 3u);
  const uint8_t* sky = Pixel(*frame, 10, 5);
  EXPECT_GT(sky[2], sky[0]);  // blue
  const uint8_t* ground = Pixel(*frame, 10, 97);
  EXPECT_GT(ground[0], ground[2]);  // brown
  EXPECT_LT(ground[0], sky[0]);
  const uint8_t* body = Pixel(*frame, 50, 50);
  EXPECT_GT(body[0], 150);  // orange
  EXPECT_LT(body[2], 100);
  // Beside the capsule (more than its radius away) is sky again.
  const uint8_t* beside = Pixel(*frame, 60, 50);
  EXPECT_GT(beside[2], beside[0]);
}

TEST(PlanarDrawingTest, FarSideIsDarkerAndTheViewFollowsTheCentre) {
  absl::StatusOr<Frame> near = DrawPlanarScene(Standing(false), 100, 100);
  absl::StatusOr<Frame> far = DrawPlanarScene(Standing(true), 100, 100);
  ASSERT_TRUE(near.ok() && far.ok());
  EXPECT_LT(Pixel(*far, 50, 50)[0], Pixel(*near, 50, 50)[0]);
  PlanarScene moved = Standing(false);
  moved.centre_x = 0.4;  // the capsule 20 pixels left of the centre
  absl::StatusOr<Frame> shifted = DrawPlanarScene(moved, 100, 100);
  ASSERT_TRUE(shifted.ok());
  EXPECT_GT(Pixel(*shifted, 30, 50)[0], 150);
  EXPECT_GT(Pixel(*shifted, 50, 50)[2], Pixel(*shifted, 50, 50)[0]);
}

TEST(PlanarDrawingTest, AnInclineRisesToTheRight) {
  PlanarScene scene;
  scene.slope = 0.2;
  scene.centre_z = 0.5;
  scene.view_height = 2.0;  // ground at row 75 under the centre
  absl::StatusOr<Frame> frame = DrawPlanarScene(scene, 100, 100);
  ASSERT_TRUE(frame.ok());
  // At x = +0.8 m (pixel 90) the ground is 0.16 m (8 pixels) higher.
  const uint8_t* right = Pixel(*frame, 90, 70);
  const uint8_t* left = Pixel(*frame, 10, 70);
  EXPECT_GT(right[0], right[2]);  // ground
  EXPECT_GT(left[2], left[0]);    // sky
}

TEST(PlanarDrawingTest, RefusesAnEmptyFrame) {
  EXPECT_FALSE(DrawPlanarScene(Standing(false), 0, 10).ok());
  PlanarScene scene = Standing(false);
  scene.view_height = 0.0;
  EXPECT_FALSE(DrawPlanarScene(scene, 10, 10).ok());
}

TEST(BulletEnvRenderTest, DrawsTheBipedAfterAReset) {
  auto env = MakeEnvironment("BipedWalkIncline");
  ASSERT_TRUE(env.ok());
  EXPECT_TRUE(absl::IsFailedPrecondition((*env)->Render(64, 48).status()));
  std::vector<double> observation((*env)->spec().observation_size);
  ASSERT_TRUE((*env)->Reset(1, absl::MakeSpan(observation)).ok());
  absl::StatusOr<Frame> frame = (*env)->Render(120, 80);
  ASSERT_TRUE(frame.ok()) << frame.status();
  EXPECT_EQ(frame->width, 120);
  EXPECT_EQ(frame->rgb.size(), 120u * 80u * 3u);
  // The body stands in the middle column, the ground at the bottom.
  int body_rows = 0;
  for (int y = 0; y < 80; ++y) {
    const uint8_t* p = Pixel(*frame, 60, y);
    body_rows += p[0] > 150 && p[2] < 100;
  }
  EXPECT_GT(body_rows, 20);
  const uint8_t* ground = Pixel(*frame, 60, 79);
  EXPECT_GT(ground[0], ground[2]);
}

}  // namespace
}  // namespace vantage
