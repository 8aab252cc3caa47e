#ifndef VANTAGE_ACTOR_ENVS_MAZE_FIRST_PERSON_MAZE_H_
#define VANTAGE_ACTOR_ENVS_MAZE_FIRST_PERSON_MAZE_H_

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

// A first-person maze in the spirit of ViZDoom's My Way Home: nine rooms
// on a 3 x 3 plan, each with walls of its own colour, joined by doorways
// into a tree (one room leads on to a dead-end corridor), seen through a
// 90-degree raycast camera as 3 x 42 x 42 RGB frames (values 0-255). The
// player moves with Doom's walking physics (thrust, friction, square
// bounding box sliding along walls) for 4 tics per step and either turns
// left, turns right, walks forward or walks backward. It starts in one of
// the seven ordinary rooms (at random, facing anywhere) and gets +1, which
// ends the episode, on touching the goal in the far room; -0.0001 per tic
// otherwise; 525 steps (2100 tics). docs/environments.md has the map.
absl::StatusOr<std::unique_ptr<Environment>> MakeFirstPersonMaze();

struct MazeLayout;

class FirstPersonMaze : public Environment {
 public:
  enum Action { kTurnLeft = 0, kTurnRight, kForward, kBackward, kActions };

  FirstPersonMaze();

  const EnvSpec& spec() const override { return spec_; }
  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override;
  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override;
  absl::StatusOr<std::string> SaveState() const override;
  absl::Status RestoreState(absl::string_view state) override;
  absl::StatusOr<Frame> Render(int width, int height) override;

  // The map's rows, north first: letters are walls (a-g the rooms episodes
  // start in, h the dead-end corridor, i the goal's room), '.' floor, 'G'
  // the goal. Cell (x, y) of the world spans [x, x + 1) x [y, y + 1) with
  // y growing northwards, so row r holds y = rows - 1 - r.
  static const std::vector<std::string>& Map();
  // Where the goal stands.
  static std::array<double, 2> Goal();

  double x() const { return x_; }
  double y() const { return y_; }
  // Radians: 0 faces east, pi / 2 north.
  double angle() const { return angle_; }

 private:
  void Tic(int action);
  void Observe(absl::Span<double> observation);

  const MazeLayout& layout_;
  EnvSpec spec_;
  double x_ = 0.0;
  double y_ = 0.0;
  double angle_ = 0.0;
  double vx_ = 0.0;
  double vy_ = 0.0;
  int turn_held_ = 0;
  bool needs_reset_ = true;
  std::vector<uint8_t> pixels_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MAZE_FIRST_PERSON_MAZE_H_
