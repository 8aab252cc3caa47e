#ifndef VANTAGE_ACTOR_RENDER_PLANAR_DRAWING_H_
#define VANTAGE_ACTOR_RENDER_PLANAR_DRAWING_H_

// Side-on pictures of planar characters made of capsules (the Bullet
// tasks), drawn in 2-D with Cairo. Knows nothing of Bullet: the caller
// describes the scene in the sagittal (x, z) plane, in metres.

#include <array>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/frame.h"

namespace vantage {

struct PlanarCapsule {
  // The capsule's segment and radius.
  double from_x = 0.0;
  double from_z = 0.0;
  double to_x = 0.0;
  double to_z = 0.0;
  double radius = 0.05;
  // On the far side of the body (a left limb seen from the right): drawn
  // first and darker.
  bool far_side = false;
};

struct PlanarScene {
  std::vector<PlanarCapsule> capsules;
  // The ground passes through the origin and rises by tan(slope) per metre
  // of x (radians)...
  double slope = 0.0;
  // ... unless this profile is given: (x, z) points from left to right,
  // joined by straight segments, spanning the frame.
  std::vector<std::array<double, 2>> ground;
  // The world point at the frame's centre, and how many metres the frame's
  // height spans.
  double centre_x = 0.0;
  double centre_z = 1.0;
  double view_height = 2.5;
};

// Sky, the ground (with a mark every metre so that motion shows while the
// view follows the body), then the capsules as thick lines with round caps.
absl::StatusOr<Frame> DrawPlanarScene(const PlanarScene& scene, int width,
                                      int height);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_RENDER_PLANAR_DRAWING_H_
