#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_RENDERER_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_RENDERER_H_

// Offscreen pictures of a MuJoCo simulation with MuJoCo's own renderer, on
// a software OpenGL context (OSMesa), so no display or GPU is needed. The
// OSMesa and OpenGL headers stay in the .cc.

#include <mujoco/mujoco.h>

#include <memory>

#include "absl/status/statusor.h"
#include "common/env/frame.h"

namespace vantage {

// Where the camera looks.
struct MujocoView {
  // A body to follow side-on (the root of a walking character), or -1:
  // the model's first fixed camera, else a free camera on the whole model.
  int track_body = -1;
};

class MujocoRenderer {
 public:
  // Renders `model`'s simulations at `width` x `height`. Keeps its own copy
  // of the model (with an offscreen buffer at least that large) and of the
  // data it draws, so rendering leaves the caller's model and data as they
  // were.
  static absl::StatusOr<std::unique_ptr<MujocoRenderer>> Create(
      const mjModel* model, int width, int height);
  ~MujocoRenderer();
  MujocoRenderer(const MujocoRenderer&) = delete;
  MujocoRenderer& operator=(const MujocoRenderer&) = delete;

  // `data` must belong to a model of the same sizes as Create's.
  absl::StatusOr<Frame> Render(const mjData* data, const MujocoView& view);

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  struct Gl;
  MujocoRenderer(int width, int height, std::unique_ptr<Gl> gl);

  int width_;
  int height_;
  std::unique_ptr<Gl> gl_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_RENDERER_H_
