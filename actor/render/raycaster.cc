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

}  // namespace

void Raycast(const RaycastScene& scene, const RaycastCamera& camera, int width,
             int height, absl::Span<uint8_t> rgb) {
  const double dir_x = std::cos(camera.angle);
  const double dir_y = std::sin(camera.angle);
  const double half_tan = std::tan(camera.field_of_view / 2.0);
  // Pixels per unit of height at unit depth (square pixels).
  const double focal = (width / 2.0) / half_tan;
  const double horizon = height / 2.0;
  std::vector<double> depth(width, std::numeric_limits<double>::infinity());

  for (int py = 0; py < height; ++py) {
    const Rgb& colour = py < horizon ? scene.ceiling : scene.floor;
    for (int px = 0; px < width; ++px) Put(rgb, width, px, py, colour, 1.0);
  }

  for (int px = 0; px < width; ++px) {
    // Through the pixel column's centre, on the camera plane at depth 1.
    const double offset = (2.0 * (px + 0.5) / width - 1.0) * half_tan;
    // The camera's right is (dir_y, -dir_x): angles grow to the left.
    const double ray_x = dir_x + offset * dir_y;
    const double ray_y = dir_y - offset * dir_x;
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
    bool y_face = false;
    uint8_t wall = 0;
    while (wall == 0) {
      if (next_x < next_y) {
        next_x += step_x_len;
        cell_x += step_x;
        y_face = false;
      } else {
        next_y += step_y_len;
        cell_y += step_y;
        y_face = true;
      }
      if (cell_x < 0 || cell_y < 0 || cell_x >= scene.columns ||
          cell_y >= scene.rows) {
        break;  // an open border: nothing to draw
      }
      wall = scene.At(cell_x, cell_y);
    }
    if (wall == 0) continue;
    // Distance along the view direction (no fish-eye).
    const double perpendicular =
        std::max(1e-6, y_face ? next_y - step_y_len : next_x - step_x_len);
    depth[px] = perpendicular;
    const double half = focal / perpendicular / 2.0;
    const int top =
        std::max(0, static_cast<int>(std::ceil(horizon - half - 0.5)));
    const int bottom =
        std::min(height, static_cast<int>(std::ceil(horizon + half - 0.5)));
    const double shade =
        (y_face ? kSideShade : 1.0) / (1.0 + kFog * perpendicular);
    const Rgb& colour = scene.wall_colours[wall - 1];
    for (int py = top; py < bottom; ++py)
      Put(rgb, width, px, py, colour, shade);
  }

  // Farthest first, so nearer sprites cover farther ones.
  std::vector<std::pair<double, const RaycastSprite*>> order;
  for (const RaycastSprite& sprite : scene.sprites) {
    const double dx = sprite.x - camera.x;
    const double dy = sprite.y - camera.y;
    const double forward = dx * dir_x + dy * dir_y;
    if (forward > 1e-3) order.emplace_back(forward, &sprite);
  }
  std::sort(order.begin(), order.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [forward, sprite] : order) {
    const double dx = sprite->x - camera.x;
    const double dy = sprite->y - camera.y;
    const double lateral = dx * dir_y - dy * dir_x;
    const double centre = width / 2.0 + focal * lateral / forward;
    const double half_width = focal * sprite->half_width / forward;
    const double floor_y = horizon + focal * 0.5 / forward;
    const double top_y = floor_y - focal * sprite->height / forward;
    const int left =
        std::max(0, static_cast<int>(std::ceil(centre - half_width - 0.5)));
    const int right =
        std::min(width, static_cast<int>(std::ceil(centre + half_width - 0.5)));
    const int top = std::max(0, static_cast<int>(std::ceil(top_y - 0.5)));
    const int bottom =
        std::min(height, static_cast<int>(std::ceil(floor_y - 0.5)));
    const double shade = 1.0 / (1.0 + kFog * forward);
    for (int px = left; px < right; ++px) {
      if (forward >= depth[px]) continue;
      for (int py = top; py < bottom; ++py) {
        Put(rgb, width, px, py, sprite->colour, shade);
      }
    }
  }
}

}  // namespace vantage
