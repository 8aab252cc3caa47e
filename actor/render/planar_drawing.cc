#include "actor/render/planar_drawing.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

struct SurfaceDeleter {
  void operator()(cairo_surface_t* surface) const {
    cairo_surface_destroy(surface);
  }
};
struct CairoDeleter {
  void operator()(cairo_t* cairo) const { cairo_destroy(cairo); }
};

struct Rgb {
  double r, g, b;
};
constexpr Rgb kSkyTop = {0.45, 0.65, 0.90};
constexpr Rgb kSkyHorizon = {0.85, 0.92, 0.98};
constexpr Rgb kGround = {0.42, 0.36, 0.28};
constexpr Rgb kGroundLine = {0.20, 0.17, 0.13};
constexpr Rgb kNearLimb = {0.85, 0.38, 0.18};
constexpr Rgb kFarLimb = {0.55, 0.24, 0.12};
constexpr Rgb kOutline = {0.15, 0.08, 0.05};

void SetColour(cairo_t* cr, const Rgb& colour) {
  cairo_set_source_rgb(cr, colour.r, colour.g, colour.b);
}

void StrokeCapsule(cairo_t* cr, const PlanarCapsule& capsule, double outline,
                   const Rgb& fill) {
  cairo_move_to(cr, capsule.from_x, capsule.from_z);
  cairo_line_to(cr, capsule.to_x, capsule.to_z);
  cairo_set_line_width(cr, 2.0 * capsule.radius + 2.0 * outline);
  SetColour(cr, kOutline);
  cairo_stroke_preserve(cr);
  cairo_set_line_width(cr, 2.0 * capsule.radius);
  SetColour(cr, fill);
  cairo_stroke(cr);
}

// The world's extent in view, in metres.
struct View {
  double left, right, bottom, top;
  double pixel;  // one pixel's size
};

void PaintSky(cairo_t* cr, const View& view) {
  std::unique_ptr<cairo_pattern_t, void (*)(cairo_pattern_t*)> sky(
      cairo_pattern_create_linear(0, view.top, 0, view.bottom),
      cairo_pattern_destroy);
  cairo_pattern_add_color_stop_rgb(sky.get(), 0, kSkyTop.r, kSkyTop.g,
                                   kSkyTop.b);
  cairo_pattern_add_color_stop_rgb(sky.get(), 1, kSkyHorizon.r, kSkyHorizon.g,
                                   kSkyHorizon.b);
  cairo_set_source(cr, sky.get());
  cairo_paint(cr);
}

// The ground below its line (the slope's, or the profile), down past the
// frame's bottom edge, with a tick every metre (longer every fifth).
void DrawGround(cairo_t* cr, const PlanarScene& scene, const View& view) {
  const double tangent = std::tan(scene.slope);
  std::vector<std::array<double, 2>> line = scene.ground;
  if (line.empty()) {
    line = {{view.left - 1.0, (view.left - 1.0) * tangent},
            {view.right + 1.0, (view.right + 1.0) * tangent}};
  }
  const auto height_at = [&](double x) {
    for (size_t i = 1; i < line.size(); ++i) {
      if (x <= line[i][0] || i + 1 == line.size()) {
        const double span = line[i][0] - line[i - 1][0];
        const double blend =
            span > 0 ? std::clamp((x - line[i - 1][0]) / span, 0.0, 1.0) : 0.0;
        return line[i - 1][1] + blend * (line[i][1] - line[i - 1][1]);
      }
    }
    return line.front()[1];
  };
  double lowest = line.front()[1];
  for (const auto& point : line) lowest = std::min(lowest, point[1]);
  const double bottom = std::min(view.bottom, lowest) - 1.0;
  const auto trace = [&] {
    cairo_move_to(cr, line.front()[0], line.front()[1]);
    for (size_t i = 1; i < line.size(); ++i) {
      cairo_line_to(cr, line[i][0], line[i][1]);
    }
  };
  trace();
  cairo_line_to(cr, line.back()[0], bottom);
  cairo_line_to(cr, line.front()[0], bottom);
  cairo_close_path(cr);
  SetColour(cr, kGround);
  cairo_fill(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  trace();
  cairo_set_line_width(cr, 3.0 * view.pixel);
  SetColour(cr, kGroundLine);
  cairo_stroke(cr);
  for (double x = std::floor(view.left); x <= view.right + 1.0; x += 1.0) {
    const bool long_tick = std::fmod(std::abs(x), 5.0) < 0.5;
    const double z = height_at(x);
    cairo_move_to(cr, x, z);
    cairo_line_to(cr, x, z - (long_tick ? 0.25 : 0.1));
    cairo_set_line_width(cr, 2.0 * view.pixel);
    cairo_stroke(cr);
  }
}

// The far side's limbs first, so that the near side's cover them.
void DrawCapsules(cairo_t* cr, const PlanarScene& scene, const View& view) {
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (bool far_side : {true, false}) {
    for (const PlanarCapsule& capsule : scene.capsules) {
      if (capsule.far_side != far_side) continue;
      StrokeCapsule(cr, capsule, 1.5 * view.pixel,
                    far_side ? kFarLimb : kNearLimb);
    }
  }
}

// CAIRO_FORMAT_RGB24 keeps each pixel as a native-endian 32-bit xRGB word.
Frame CopyPixels(cairo_surface_t* surface, int width, int height) {
  Frame frame;
  frame.width = width;
  frame.height = height;
  frame.rgb.resize(static_cast<size_t>(width) * height * 3);
  const unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  uint8_t* out = frame.rgb.data();
  for (int y = 0; y < height; ++y) {
    const unsigned char* row = data + static_cast<size_t>(y) * stride;
    for (int x = 0; x < width; ++x) {
      uint32_t pixel_word;
      std::memcpy(&pixel_word, row + 4 * x, sizeof(pixel_word));
      *out++ = static_cast<uint8_t>(pixel_word >> 16);
      *out++ = static_cast<uint8_t>(pixel_word >> 8);
      *out++ = static_cast<uint8_t>(pixel_word);
    }
  }
  return frame;
}

}  // namespace

absl::StatusOr<Frame> DrawPlanarScene(const PlanarScene& scene, int width,
                                      int height) {
  if (width < 1 || height < 1 || !(scene.view_height > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("planar drawing: a frame of ", width, "x", height,
                     " pixels spanning ", scene.view_height, " m"));
  }
  std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height));
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "planar drawing: cannot create a ", width, "x", height, " surface: ",
        cairo_status_to_string(cairo_surface_status(surface.get()))));
  }
  std::unique_ptr<cairo_t, CairoDeleter> context(cairo_create(surface.get()));
  cairo_t* cr = context.get();

  // Pixels to world: x to the right, z up, the scene's centre in the middle.
  const double scale = height / scene.view_height;
  const double half_width = 0.5 * width / scale;
  const double half_height = 0.5 * scene.view_height;
  const View view{scene.centre_x - half_width, scene.centre_x + half_width,
                  scene.centre_z - half_height, scene.centre_z + half_height,
                  1.0 / scale};
  cairo_translate(cr, 0.5 * width, 0.5 * height);
  cairo_scale(cr, scale, -scale);
  cairo_translate(cr, -scene.centre_x, -scene.centre_z);
  PaintSky(cr, view);
  DrawGround(cr, scene, view);
  DrawCapsules(cr, scene, view);
  cairo_surface_flush(surface.get());
  if (cairo_status(cr) != CAIRO_STATUS_SUCCESS) {
    return absl::InternalError(absl::StrCat(
        "planar drawing: ", cairo_status_to_string(cairo_status(cr))));
  }
  return CopyPixels(surface.get(), width, height);
}

}  // namespace vantage
