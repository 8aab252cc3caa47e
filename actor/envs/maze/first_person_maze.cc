#include "actor/envs/maze/first_person_maze.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/render/raycaster.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr int kCells = 19;
constexpr int kStartRooms = 7;  // a-g, on the 3 x 3 plan in reading order

const std::vector<Rgb>& WallColours() {
  static const auto* colours = new std::vector<Rgb>{
      {200, 40, 40},  {40, 170, 60},   {50, 80, 210},
      {210, 200, 40}, {180, 50, 180},  {40, 190, 200},
      {230, 130, 30}, {120, 120, 120}, {235, 235, 235},
  };
  return *colours;
}

// Doom's constants (linuxdoom-1.10 p_user.c, g_game.c, p_mobj.c,
// p_local.h, info.c), in cells of 64 units and tics of 1/35 s.
constexpr double kUnit = 1.0 / 64.0;
constexpr double kPlayerRadius = 16 * kUnit;
constexpr double kGoalRadius = 20 * kUnit;  // the green armour vest
// Walking: forwardmove 0x19 x 2048 / 65536 units per tic per tic.
constexpr double kThrust = 25.0 * 2048.0 / 65536.0 * kUnit;
constexpr double kFriction = 0xE800 / 65536.0;
constexpr double kStopSpeed = 0x1000 / 65536.0 * kUnit;
constexpr double kMaxMove = 30 * kUnit;
// angleturn {640, 1280, 320} in 1/65536 of a turn: walking turns at 640
// per tic, slowly (320) until a turn has been held SLOWTURNTICS (6) tics.
constexpr double kTurn = 640.0 / 65536.0 * 2.0 * M_PI;
constexpr double kSlowTurn = 320.0 / 65536.0 * 2.0 * M_PI;
constexpr int kSlowTurnTics = 6;
constexpr int kTicsPerStep = 4;
constexpr double kLivingReward = -0.0001;
constexpr int kEpisodeSteps = 525;
constexpr int kFrameSize = 42;
constexpr double kFieldOfView = M_PI / 2.0;

constexpr char kStateKind[] = "first_person_maze";
constexpr uint32_t kStateVersion = 1;

}  // namespace

struct MazeLayout {
  RaycastScene scene;
  double goal_x = 0.0;
  double goal_y = 0.0;
  std::array<std::array<double, 2>, kStartRooms> room_centres{};
};

namespace {

const MazeLayout& TheLayout() {
  static const MazeLayout* layout = [] {
    auto* out = new MazeLayout;
    RaycastScene& scene = out->scene;
    scene.columns = kCells;
    scene.rows = kCells;
    scene.cells.assign(kCells * kCells, 0);
    scene.wall_colours = WallColours();
    scene.floor = {70, 60, 50};
    scene.ceiling = {35, 35, 45};
    for (int row = 0; row < kCells; ++row) {
      // y grows northwards: the first text row is the top.
      const int y = kCells - 1 - row;
      for (int x = 0; x < kCells; ++x) {
        const char c = FirstPersonMaze::Map()[row][x];
        if (c >= 'a' && c <= 'i') scene.cells[y * kCells + x] = c - 'a' + 1;
        if (c == 'G') {
          out->goal_x = x + 0.5;
          out->goal_y = y + 0.5;
        }
      }
    }
    scene.sprites.push_back(RaycastSprite{out->goal_x, out->goal_y, kGoalRadius,
                                          0.45, Rgb{60, 230, 60}});
    for (int room = 0; room < kStartRooms; ++room) {
      const int plan_row = room / 3;
      const int plan_column = room % 3;
      out->room_centres[room] = {6.0 * plan_column + 3.5,
                                 kCells - (6.0 * plan_row + 3.5)};
    }
    return out;
  }();
  return *layout;
}

RaycastCamera CameraAt(double x, double y, double angle) {
  RaycastCamera camera;
  camera.x = x;
  camera.y = y;
  camera.angle = angle;
  camera.field_of_view = kFieldOfView;
  return camera;
}

bool Blocked(const RaycastScene& scene, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x - kPlayerRadius));
  const int x1 = static_cast<int>(std::floor(x + kPlayerRadius));
  const int y0 = static_cast<int>(std::floor(y - kPlayerRadius));
  const int y1 = static_cast<int>(std::floor(y + kPlayerRadius));
  for (int cy = y0; cy <= y1; ++cy) {
    for (int cx = x0; cx <= x1; ++cx) {
      if (cx < 0 || cy < 0 || cx >= scene.columns || cy >= scene.rows ||
          scene.At(cx, cy) != 0) {
        return true;
      }
    }
  }
  return false;
}

}  // namespace

// Top view, north up: one character per cell of 64 Doom units (a room is
// 320 units across, a doorway 64).
const std::vector<std::string>& FirstPersonMaze::Map() {
  static const auto* map = new std::vector<std::string>{
      "aaaaaaabbbbbbcccccc",  //
      "a.....a.....b.....c",  //
      "a.....a.....b.....c",  //
      "a.................c",  //
      "a.....a.....b.....c",  //
      "a.....a.....b.....c",  //
      "aaa.aaabb.bbbcccccc",  //
      "d.....d.....e.....f",  //
      "d.....d.....e.....f",  //
      "d.....d...........f",  //
      "d.....d.....e.....f",  //
      "d.....d.....e.....f",  //
      "ddd.dddeeeeeeff.fff",  //
      "g.....ghhhhhh.....i",  //
      "g.....ghhhhhh.....i",  //
      "g...........h..G..i",  //
      "g.....ghhhhhh.....i",  //
      "g.....ghhhhhh.....i",  //
      "ggggggghhhhhhiiiiii",  //
  };
  return *map;
}

std::array<double, 2> FirstPersonMaze::Goal() {
  return {TheLayout().goal_x, TheLayout().goal_y};
}

FirstPersonMaze::FirstPersonMaze() : layout_(TheLayout()) {
  spec_.name = "FirstPersonMaze";
  spec_.observation_size = 3 * kFrameSize * kFrameSize;
  spec_.observation_shape = {3, kFrameSize, kFrameSize};
  spec_.observation_high = 255;
  spec_.discrete = true;
  spec_.action_size = kActions;
  spec_.max_episode_steps = kEpisodeSteps;
  spec_.control_dt = kTicsPerStep / 35.0;
  pixels_.resize(3 * kFrameSize * kFrameSize);
  // A valid pose before the first Reset, so that a state saved then
  // restores.
  x_ = layout_.room_centres[0][0];
  y_ = layout_.room_centres[0][1];
}

absl::Status FirstPersonMaze::Reset(uint64_t seed,
                                    absl::Span<double> observation) {
  if (absl::Status status = CheckObservationBuffer(spec_, observation);
      !status.ok()) {
    return status;
  }
  std::mt19937_64 random(seed);
  const auto& centre = layout_.room_centres[std::uniform_int_distribution<int>(
      0, kStartRooms - 1)(random)];
  std::uniform_real_distribution<double> offset(-1.5, 1.5);
  x_ = centre[0] + offset(random);
  y_ = centre[1] + offset(random);
  angle_ = std::uniform_real_distribution<double>(-M_PI, M_PI)(random);
  vx_ = vy_ = 0.0;
  turn_held_ = 0;
  needs_reset_ = false;
  Observe(observation);
  return absl::OkStatus();
}

absl::StatusOr<StepResult> FirstPersonMaze::Step(
    absl::Span<const double> action, absl::Span<double> observation) {
  if (absl::Status status = CheckStep(spec_, needs_reset_, action, observation);
      !status.ok()) {
    return status;
  }
  const int chosen = static_cast<int>(action[0]);
  StepResult result;
  for (int tic = 0; tic < kTicsPerStep && !result.terminated; ++tic) {
    Tic(chosen);
    result.reward += kLivingReward;
    if (std::abs(x_ - layout_.goal_x) < kPlayerRadius + kGoalRadius &&
        std::abs(y_ - layout_.goal_y) < kPlayerRadius + kGoalRadius) {
      result.reward += 1.0;
      result.terminated = true;
    }
  }
  if (result.terminated) needs_reset_ = true;
  Observe(observation);
  return result;
}

absl::StatusOr<std::string> FirstPersonMaze::SaveState() const {
  StateWriter writer(kStateKind, kStateVersion);
  writer.PutBool(needs_reset_);
  writer.PutDoubles({x_, y_, angle_, vx_, vy_});
  writer.PutI64(turn_held_);
  return std::move(writer).Finish();
}

absl::Status FirstPersonMaze::RestoreState(absl::string_view state) {
  const std::string context = absl::StrCat(spec_.name, ": saved state");
  StateReader reader(state, kStateKind, kStateVersion, context);
  const bool needs_reset = reader.GetBool("needs_reset");
  const std::vector<double> values = reader.GetDoubles("pose", 5);
  const int64_t turn_held = reader.GetI64("turn_held");
  if (absl::Status status = reader.Finish(); !status.ok()) return status;
  const auto invalid = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(context, ": ", why));
  };
  for (double v : values) {
    if (!std::isfinite(v)) return invalid("a non-finite pose or velocity");
  }
  // Inside the map before anything converts the position to cells.
  const double inside = kPlayerRadius;
  if (!(values[0] > inside && values[0] < kCells - inside &&
        values[1] > inside && values[1] < kCells - inside)) {
    return invalid(absl::StrCat("the player at (", values[0], ", ", values[1],
                                ") is outside the map"));
  }
  if (Blocked(layout_.scene, values[0], values[1])) {
    return invalid(absl::StrCat("the player at (", values[0], ", ", values[1],
                                ") would overlap a wall"));
  }
  if (std::abs(values[2]) > M_PI) {
    return invalid(absl::StrCat("angle ", values[2], " is not in [-pi, pi]"));
  }
  if (std::abs(values[3]) > kMaxMove || std::abs(values[4]) > kMaxMove) {
    return invalid("a speed above Doom's limit of 30 units per tic");
  }
  if (turn_held < 0 || turn_held > kSlowTurnTics) {
    return invalid(absl::StrCat("turn_held ", turn_held, " is not in [0, ",
                                kSlowTurnTics, "]"));
  }
  needs_reset_ = needs_reset;
  x_ = values[0];
  y_ = values[1];
  angle_ = values[2];
  vx_ = values[3];
  vy_ = values[4];
  turn_held_ = static_cast<int>(turn_held);
  return absl::OkStatus();
}

absl::StatusOr<Frame> FirstPersonMaze::Render(int width, int height) {
  if (width < 1 || height < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec_.name, ": a picture needs at least 1 x 1 pixels, got ", width,
        " x ", height));
  }
  Frame frame;
  frame.width = width;
  frame.height = height;
  frame.rgb.resize(3 * static_cast<size_t>(width) * height);
  Raycast(layout_.scene, CameraAt(x_, y_, angle_), width, height,
          absl::MakeSpan(frame.rgb));
  return frame;
}

// One tic of Doom's player movement: turn, thrust, move (each axis on its
// own, so the box slides along walls), friction.
void FirstPersonMaze::Tic(int action) {
  if (action == kTurnLeft || action == kTurnRight) {
    // Counted before the check, as G_BuildTiccmd does: 5 slow tics.
    turn_held_ = std::min(turn_held_ + 1, kSlowTurnTics);
    const double rate = turn_held_ < kSlowTurnTics ? kSlowTurn : kTurn;
    angle_ += action == kTurnLeft ? rate : -rate;
    angle_ = std::remainder(angle_, 2.0 * M_PI);
  } else {
    turn_held_ = 0;
  }
  const bool walking = action == kForward || action == kBackward;
  if (walking) {
    const double thrust = action == kForward ? kThrust : -kThrust;
    vx_ += thrust * std::cos(angle_);
    vy_ += thrust * std::sin(angle_);
  }
  vx_ = std::clamp(vx_, -kMaxMove, kMaxMove);
  vy_ = std::clamp(vy_, -kMaxMove, kMaxMove);
  if (!Blocked(layout_.scene, x_ + vx_, y_)) {
    x_ += vx_;
  } else {
    vx_ = 0.0;
  }
  if (!Blocked(layout_.scene, x_, y_ + vy_)) {
    y_ += vy_;
  } else {
    vy_ = 0.0;
  }
  // P_XYMovement: a slow body with no move command stops instead of
  // slowing down.
  if (!walking && std::abs(vx_) < kStopSpeed && std::abs(vy_) < kStopSpeed) {
    vx_ = vy_ = 0.0;
  } else {
    vx_ *= kFriction;
    vy_ *= kFriction;
  }
}

// Channel-major [3, 42, 42], the layout convolutions take, from the
// renderer's packed rows.
void FirstPersonMaze::Observe(absl::Span<double> observation) {
  Raycast(layout_.scene, CameraAt(x_, y_, angle_), kFrameSize, kFrameSize,
          absl::MakeSpan(pixels_));
  const int plane = kFrameSize * kFrameSize;
  for (int i = 0; i < plane; ++i) {
    for (int c = 0; c < 3; ++c) observation[c * plane + i] = pixels_[3 * i + c];
  }
}

absl::StatusOr<std::unique_ptr<Environment>> MakeFirstPersonMaze() {
  return std::unique_ptr<Environment>(new FirstPersonMaze());
}

}  // namespace vantage
