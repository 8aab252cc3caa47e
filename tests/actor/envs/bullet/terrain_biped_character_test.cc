#include "actor/envs/bullet/terrain_biped_character.h"

#include <algorithm>
#include <cmath>

#include "gtest/gtest.h"

namespace vantage {
namespace {

constexpr int kRightFoot = 3;
constexpr int kLeftFoot = 6;

TEST(TerrainBipedCharacterTest, WeighsWhatTheCharacterFileSays) {
  double mass = 0.0;
  for (const TerrainBipedBody& body : TerrainBipedBodyDefs()) {
    mass += body.mass;
  }
  EXPECT_DOUBLE_EQ(mass, 49.0);
  // Parents come first, so one pass places every frame.
  const auto& joints = TerrainBipedJointDefs();
  for (int j = 1; j < kTerrainBipedBodies; ++j) {
    EXPECT_GE(joints[j].parent, 0);
    EXPECT_LT(joints[j].parent, j);
    EXPECT_LT(joints[j].lower, joints[j].upper) << joints[j].name;
  }
}

// The clip was made for this character: through the whole stride the
// lower foot rests on the ground (y = 0) and nothing else comes near it,
// which checks the transcribed offsets, sizes and angle conventions
// together.
TEST(TerrainBipedCharacterTest, TheWalkingClipKeepsAFootOnTheGround) {
  for (int i = 0; i <= 100; ++i) {
    const double time = i * 0.01;
    const auto bodies = PlaceBodies(WalkPose(time));
    const double feet = std::min(LowestCorner(kRightFoot, bodies[kRightFoot]),
                                 LowestCorner(kLeftFoot, bodies[kLeftFoot]));
    // Measured: between -2.5 and +7.7 mm.
    EXPECT_NEAR(feet, 0.0, 0.01) << "t=" << time;
    for (int b = 0; b < kTerrainBipedBodies; ++b) {
      if (b == kRightFoot || b == kLeftFoot) continue;
      EXPECT_GT(LowestCorner(b, bodies[b]), 0.02)
          << TerrainBipedBodyDefs()[b].name << " at t=" << time;
    }
  }
}

// Half a stride later the legs have swapped: a check of the transcription.
TEST(TerrainBipedCharacterTest, HalfAStrideLaterTheLegsHaveSwapped) {
  for (int k = 0; k < 5; ++k) {
    const TerrainBipedPose now = WalkPose(0.1 * k);
    const TerrainBipedPose later = WalkPose(0.1 * k + 0.5);
    for (int j : {0, 1}) {  // hip, knee
      EXPECT_NEAR(later.joints[j], now.joints[j + 3], 1e-9) << k;
      EXPECT_NEAR(later.joints[j + 3], now.joints[j], 1e-9) << k;
    }
    EXPECT_NEAR(later.root_y, now.root_y, 1e-9);
  }
}

TEST(TerrainBipedCharacterTest, TheClipLoopsAt1point535MetresASecond) {
  EXPECT_NEAR(WalkCycleAdvance(), 1.53532, 1e-12);
  const TerrainBipedPose a = WalkPose(0.25);
  const TerrainBipedPose b = WalkPose(2.25);
  EXPECT_NEAR(b.root_x - a.root_x, 2 * WalkCycleAdvance(), 1e-12);
  EXPECT_DOUBLE_EQ(b.root_y, a.root_y);
  // Between key poses: linear.
  const TerrainBipedPose k0 = WalkPose(0.0);
  const TerrainBipedPose k1 = WalkPose(0.1);
  const TerrainBipedPose mid = WalkPose(0.05);
  EXPECT_NEAR(mid.root_x, (k0.root_x + k1.root_x) / 2, 1e-12);
  EXPECT_NEAR(mid.joints[4], (k0.joints[4] + k1.joints[4]) / 2, 1e-12);
  // The hips sit on the root; the knee 0.352 m down the thigh.
  const auto hip = JointPosition(k0, 1);
  EXPECT_DOUBLE_EQ(hip[0], k0.root_x);
  EXPECT_DOUBLE_EQ(hip[1], k0.root_y);
  const auto knee = JointPosition(k0, 2);
  EXPECT_NEAR(std::hypot(knee[0] - hip[0], knee[1] - hip[1]), 0.352, 1e-12);
  EXPECT_GT(knee[0], hip[0]);  // a positive hip angle swings forward
}

}  // namespace
}  // namespace vantage
