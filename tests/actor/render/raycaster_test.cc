#include "actor/render/raycaster.h"

#include <cmath>
#include <vector>

#include "gtest/gtest.h"

namespace vantage {
namespace {

constexpr Rgb kEast = {200, 0, 0};
constexpr Rgb kNorth = {0, 200, 0};
constexpr Rgb kWest = {0, 0, 200};
constexpr Rgb kSouth = {200, 200, 0};

// An open square of `size` x `size` cells inside walls coloured by side.
RaycastScene Box(int size) {
  RaycastScene scene;
  scene.columns = scene.rows = size + 2;
  scene.cells.assign(scene.columns * scene.rows, 0);
  scene.wall_colours = {kEast, kNorth, kWest, kSouth};
  scene.floor = {10, 10, 10};
  scene.ceiling = {20, 20, 20};
  for (int i = 0; i < scene.rows; ++i) {
    scene.cells[i * scene.columns + scene.columns - 1] = 1;
    scene.cells[i * scene.columns + 0] = 3;
  }
  for (int x = 1; x < scene.columns - 1; ++x) {
    scene.cells[(scene.rows - 1) * scene.columns + x] = 2;
    scene.cells[x] = 4;
  }
  return scene;
}

struct Picture {
  int width;
  int height;
  std::vector<uint8_t> rgb;
  const uint8_t* At(int x, int y) const { return &rgb[3 * (y * width + x)]; }
  // Which colour dominates a pixel: 0 red, 1 green, 2 blue, -1 none.
  int Hue(int x, int y) const {
    const uint8_t* p = At(x, y);
    if (p[0] > 40 && p[1] > 40 && p[2] < 20) return 3;  // yellow
    for (int c = 0; c < 3; ++c) {
      if (p[c] > 40 && p[(c + 1) % 3] < 20 && p[(c + 2) % 3] < 20) return c;
    }
    return -1;
  }
  // Rows of wall in one column.
  int WallRows(int x) const {
    int rows = 0;
    for (int y = 0; y < height; ++y) rows += Hue(x, y) >= 0;
    return rows;
  }
};

Picture Shoot(const RaycastScene& scene, double x, double y, double angle,
              int width = 64, int height = 64) {
  Picture picture{width, height, std::vector<uint8_t>(3 * width * height)};
  RaycastCamera camera;
  camera.x = x;
  camera.y = y;
  camera.angle = angle;
  Raycast(scene, camera, width, height, absl::MakeSpan(picture.rgb));
  return picture;
}

TEST(RaycasterTest, EachDirectionSeesItsWall) {
  const RaycastScene scene = Box(8);
  const double c = 5.0;
  EXPECT_EQ(Shoot(scene, c, c, 0.0).Hue(32, 32), 0);
  EXPECT_EQ(Shoot(scene, c, c, M_PI / 2).Hue(32, 32), 1);
  EXPECT_EQ(Shoot(scene, c, c, M_PI).Hue(32, 32), 2);
  EXPECT_EQ(Shoot(scene, c, c, -M_PI / 2).Hue(32, 32), 3);
  // Floor below, ceiling above.
  const Picture picture = Shoot(scene, c, c, 0.0);
  EXPECT_EQ(picture.At(32, 0)[0], 20);
  EXPECT_EQ(picture.At(32, 63)[0], 10);
}

TEST(RaycasterTest, TurnedLeftOfACornerTheLeftWallIsOnTheLeft) {
  // Facing north-east from the middle: north's wall on the left half,
  // east's on the right.
  const Picture picture = Shoot(Box(8), 5.0, 5.0, M_PI / 4);
  EXPECT_EQ(picture.Hue(4, 32), 1);
  EXPECT_EQ(picture.Hue(59, 32), 0);
}

TEST(RaycasterTest, WallsShrinkWithDistanceWithoutFishEye) {
  const RaycastScene scene = Box(16);
  // The east wall's face is at x = 17: 4 and 8 units away. With a
  // 90-degree view 64 pixels wide, a unit-tall wall at depth d spans
  // 32 / d rows.
  EXPECT_NEAR(Shoot(scene, 13.0, 8.5, 0.0).WallRows(32), 8, 1);
  EXPECT_NEAR(Shoot(scene, 9.0, 8.5, 0.0).WallRows(32), 4, 1);
  // A flat wall seen square-on spans the same rows at the picture's edge
  // as in its middle.
  const Picture near = Shoot(scene, 13.0, 8.5, 0.0);
  EXPECT_NEAR(near.WallRows(2), near.WallRows(32), 1);
}

TEST(RaycasterTest, SpritesStandOnTheFloorAndHideBehindWalls) {
  RaycastScene scene = Box(8);
  // Half a unit tall, 4 units away: rows 32-35 of 64, from the horizon
  // down to where the floor meets it.
  scene.sprites.push_back({7.0, 5.5, 0.3, 0.5, Rgb{0, 250, 250}});
  const Picture seen = Shoot(scene, 3.0, 5.5, 0.0);
  for (int y : {32, 35}) {
    EXPECT_GT(seen.At(32, y)[1], 100) << y;
    EXPECT_GT(seen.At(32, y)[2], 100) << y;
  }
  for (int y : {30, 37}) EXPECT_LT(seen.At(32, y)[1], 100) << y;
  // A wall between camera and sprite hides it.
  scene.cells[5 * scene.columns + 5] = 3;
  const Picture hidden = Shoot(scene, 3.0, 5.5, 0.0);
  EXPECT_EQ(hidden.Hue(32, 34), 2);
  // The same scene and camera give the same bytes.
  EXPECT_EQ(hidden.rgb, Shoot(scene, 3.0, 5.5, 0.0).rgb);
}

}  // namespace
}  // namespace vantage
