#ifndef VANTAGE_ACTOR_RENDER_RAYCASTER_H_
#define VANTAGE_ACTOR_RENDER_RAYCASTER_H_

// First-person pictures of a grid world, Wolfenstein-style: one ray per
// pixel column walks the grid cell by cell (a digital differential
// analyser) to the first wall; walls are one unit tall with the eye half
// way up, shaded by which face was hit and by distance; upright sprites
// (drawn where nearer than the wall) stand on the floor. Deterministic:
// the same scene and camera give the same bytes.

#include <array>
#include <cstdint>
#include <vector>

#include "absl/types/span.h"

namespace vantage {

using Rgb = std::array<uint8_t, 3>;

struct RaycastSprite {
  double x = 0.0;
  double y = 0.0;
  double half_width = 0.2;
  double height = 0.5;
  Rgb colour = {0, 0, 0};
};

struct RaycastScene {
  // cells[y * columns + x]: 0 is open floor, k > 0 a wall drawn in
  // wall_colours[k - 1]. Cell (x, y) spans [x, x + 1) x [y, y + 1). The
  // grid's border must be walls (rays stop there).
  int columns = 0;
  int rows = 0;
  std::vector<uint8_t> cells;
  std::vector<Rgb> wall_colours;
  Rgb floor = {0, 0, 0};
  Rgb ceiling = {0, 0, 0};
  std::vector<RaycastSprite> sprites;

  uint8_t At(int x, int y) const { return cells[y * columns + x]; }
};

struct RaycastCamera {
  double x = 0.0;
  double y = 0.0;
  // Radians: 0 looks along +x, pi / 2 along +y; growing turns left
  // (seen from above with y pointing up).
  double angle = 0.0;
  double field_of_view = 1.5707963267948966;  // horizontal, radians
};

// Writes a `width` x `height` picture as packed RGB rows, top row first
// (rgb.size() == 3 * width * height).
void Raycast(const RaycastScene& scene, const RaycastCamera& camera, int width,
             int height, absl::Span<uint8_t> rgb);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_RENDER_RAYCASTER_H_
