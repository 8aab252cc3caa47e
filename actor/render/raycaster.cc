#include "actor/render/raycaster.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vantage {
namespace {

// Far walls fade towards the floor colour's darkness: a depth cue a small
// picture otherwise lacks.
constexpr double kFog = 0.12;
constexpr double kSideShade = 0.7;

uint8_t Scale(uint8_t value, double factor) {
  return static_cast<uint8_t>(
      std::lround(std::clamp(value * factor, 0.0, 255.0)));
}

void Put(absl::Span<uint8_t> rgb, int width, int px, int py, const Rgb& colour,
         double factor) {
  uint8_t* pixel = &rgb[3 * (static_cast<size_t>(py) * width + px)];
  for (int c = 0; c < 3; ++c) pixel[c] = Scale(colour[c], factor);
}

// What every pass needs to place a point of the scene on the picture.
struct View {
  const RaycastCamera& camera;
  int width;
  int height;
  absl::Span<uint8_t> rgb;
  double dir_x;
  double dir_y;
  double half_tan;
  // Pixels per unit of height at unit depth (square pixels).
  double focal;
  double horizon;
};

void FillBackground(const RaycastScene& scene, const View& view) {
  for (int py = 0; py < view.height; ++py) {
    const Rgb& colour = py < view.horizon ? scene.ceiling : scene.floor;
    for (int px = 0; px < view.width; ++px) {
      Put(view.rgb, view.width, px, py, colour, 1.0);
    }
  }
}

struct WallHit {
  uint8_t wall = 0;  // 0: the ray left the grid through an open border
  bool y_face = false;
  // Distance along the view direction (no fish-eye).
  double perpendicular = 0.0;
};

WallHit CastRay(const RaycastScene& scene, const RaycastCamera& camera,
                double ray_x, double ray_y) {
  int cell_x = static_cast<int>(std::floor(camera.x));
  int cell_y = static_cast<int>(std::floor(camera.y));
  const double step_x_len = ray_x == 0.0 ? 1e30 : std::abs(1.0 / ray_x);
  const double step_y_len = ray_y == 0.0 ? 1e30 : std::abs(1.0 / ray_y);
  const int step_x = ray_x < 0 ? -1 : 1;
  const int step_y = ray_y < 0 ? -1 : 1;
  double next_x = ray_x < 0 ? (camera.x - cell_x) * step_x_len
                            : (cell_x + 1.0 - camera.x) * step_x_len;
  double next_y = ray_y < 0 ? (camera.y - cell_y) * step_y_len
                            : (cell_y + 1.0 - camera.y) * step_y_len;
  WallHit hit;
  while (hit.wall == 0) {
    if (next_x < next_y) {
      next_x += step_x_len;
      cell_x += step_x;
      hit.y_face = false;
    } else {
      next_y += step_y_len;
      cell_y += step_y;
      hit.y_face = true;
    }
    if (cell_x < 0 || cell_y < 0 || cell_x >= scene.columns ||
        cell_y >= scene.rows) {
      return hit;
    }
    hit.wall = scene.At(cell_x, cell_y);
  }
  hit.perpendicular =
      std::max(1e-6, hit.y_face ? next_y - step_y_len : next_x - step_x_len);
  return hit;
}

// Returns each column's wall distance (infinity where no wall was drawn),
// which hides the sprites behind it.
std::vector<double> DrawWalls(const RaycastScene& scene, const View& view) {
  std::vector<double> depth(view.width,
                            std::numeric_limits<double>::infinity());
  for (int px = 0; px < view.width; ++px) {
    // Through the pixel column's centre, on the camera plane at depth 1.
    const double offset = (2.0 * (px + 0.5) / view.width - 1.0) * view.half_tan;
    // The camera's right is (dir_y, -dir_x): angles grow to the left.
    const double ray_x = view.dir_x + offset * view.dir_y;
    const double ray_y = view.dir_y - offset * view.dir_x;
    const WallHit hit = CastRay(scene, view.camera, ray_x, ray_y);
    if (hit.wall == 0) continue;
    depth[px] = hit.perpendicular;
    const double half = view.focal / hit.perpendicular / 2.0;
    const int top =
        std::max(0, static_cast<int>(std::ceil(view.horizon - half - 0.5)));
    const int bottom = std::min(
        view.height, static_cast<int>(std::ceil(view.horizon + half - 0.5)));
    const double shade =
        (hit.y_face ? kSideShade : 1.0) / (1.0 + kFog * hit.perpendicular);
    const Rgb& colour = scene.wall_colours[hit.wall - 1];
    for (int py = top; py < bottom; ++py) {
      Put(view.rgb, view.width, px, py, colour, shade);
    }
  }
  return depth;
}

void DrawSprite(const RaycastSprite& sprite, double forward,
                const std::vector<double>& depth, const View& view) {
  const double dx = sprite.x - view.camera.x;
  const double dy = sprite.y - view.camera.y;
  const double lateral = dx * view.dir_y - dy * view.dir_x;
  const double centre = view.width / 2.0 + view.focal * lateral / forward;
  const double half_width = view.focal * sprite.half_width / forward;
  const double floor_y = view.horizon + view.focal * 0.5 / forward;
  const double top_y = floor_y - view.focal * sprite.height / forward;
  const int left =
      std::max(0, static_cast<int>(std::ceil(centre - half_width - 0.5)));
  const int right = std::min(
      view.width, static_cast<int>(std::ceil(centre + half_width - 0.5)));
  const int top = std::max(0, static_cast<int>(std::ceil(top_y - 0.5)));
  const int bottom =
      std::min(view.height, static_cast<int>(std::ceil(floor_y - 0.5)));
  const double shade = 1.0 / (1.0 + kFog * forward);
  for (int px = left; px < right; ++px) {
    if (forward >= depth[px]) continue;
    for (int py = top; py < bottom; ++py) {
      Put(view.rgb, view.width, px, py, sprite.colour, shade);
    }
  }
}

void DrawSprites(const RaycastScene& scene, const std::vector<double>& depth,
                 const View& view) {
  // Farthest first, so nearer sprites cover farther ones.
  std::vector<std::pair<double, const RaycastSprite*>> order;
  for (const RaycastSprite& sprite : scene.sprites) {
    const double dx = sprite.x - view.camera.x;
    const double dy = sprite.y - view.camera.y;
    const double forward = dx * view.dir_x + dy * view.dir_y;
    if (forward > 1e-3) order.emplace_back(forward, &sprite);
  }
  std::sort(order.begin(), order.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [forward, sprite] : order) {
    DrawSprite(*sprite, forward, depth, view);
  }
}

}  // namespace

void Raycast(const RaycastScene& scene, const RaycastCamera& camera, int width,
             int height, absl::Span<uint8_t> rgb) {
  const double dir_x = std::cos(camera.angle);
  const double dir_y = std::sin(camera.angle);
  const double half_tan = std::tan(camera.field_of_view / 2.0);
  const double focal = (width / 2.0) / half_tan;
  const double horizon = height / 2.0;
  const View view{camera, width,    height, rgb,    dir_x,
                  dir_y,  half_tan, focal,  horizon};
  FillBackground(scene, view);
  const std::vector<double> depth = DrawWalls(scene, view);
  DrawSprites(scene, depth, view);
}

}  // namespace vantage
