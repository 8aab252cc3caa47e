#include "actor/envs/maze/first_person_maze.h"

#include <cmath>
#include <deque>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/util/state_bytes.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;
using Cell = std::pair<int, int>;  // (x, y), y north

constexpr int kObservation = 3 * 42 * 42;

bool Open(int x, int y) {
  const std::vector<std::string>& map = FirstPersonMaze::Map();
  const int rows = static_cast<int>(map.size());
  if (x < 0 || y < 0 || y >= rows || x >= static_cast<int>(map[0].size())) {
    return false;
  }
  const char c = map[rows - 1 - y][x];
  return c == '.' || c == 'G';
}

// The cells of a shortest 4-connected path from `from` to the goal's cell.
std::vector<Cell> PathToGoal(Cell from) {
  const std::array<double, 2> goal = FirstPersonMaze::Goal();
  const Cell target = {static_cast<int>(goal[0]), static_cast<int>(goal[1])};
  std::map<Cell, Cell> parent = {{from, from}};
  std::deque<Cell> frontier = {from};
  while (!frontier.empty()) {
    const Cell cell = frontier.front();
    frontier.pop_front();
    if (cell == target) break;
    for (const Cell& step :
         {Cell{1, 0}, Cell{-1, 0}, Cell{0, 1}, Cell{0, -1}}) {
      const Cell next = {cell.first + step.first, cell.second + step.second};
      if (Open(next.first, next.second) && parent.count(next) == 0) {
        parent[next] = cell;
        frontier.push_back(next);
      }
    }
  }
  if (parent.count(target) == 0) return {};
  std::vector<Cell> path = {target};
  while (path.back() != from) path.push_back(parent[path.back()]);
  return {path.rbegin(), path.rend()};
}

TEST(FirstPersonMazeTest, NineColouredRoomsJoinedAsATreeWithADeadEnd) {
  const std::vector<std::string>& map = FirstPersonMaze::Map();
  ASSERT_EQ(map.size(), 19u);
  std::map<char, int> walls;
  int goals = 0;
  for (const std::string& row : map) {
    ASSERT_EQ(row.size(), 19u);
    for (char c : row) {
      if (c >= 'a' && c <= 'i') ++walls[c];
      goals += c == 'G';
    }
  }
  EXPECT_EQ(walls.size(), 9u);
  EXPECT_EQ(goals, 1);
  // Every open cell reaches the goal: one connected maze.
  for (int y = 0; y < 19; ++y) {
    for (int x = 0; x < 19; ++x) {
      if (Open(x, y)) EXPECT_FALSE(PathToGoal({x, y}).empty()) << x << "," << y;
    }
  }
  // From the first room the way leads through three more rooms.
  EXPECT_EQ(PathToGoal({3, 15}).size(), 25u);
}

TEST(FirstPersonMazeTest, WalkingAndTurningFollowDoomsPhysics) {
  FirstPersonMaze env;
  std::vector<double> observation(kObservation);
  ASSERT_TRUE(env.Reset(1, absl::MakeSpan(observation)).ok());
  // Turn: the first 5 tics a turn is held are slow (320/65536 of a turn),
  // then 640.
  const double slow = 320.0 / 65536.0 * 2 * M_PI;
  const double fast = 640.0 / 65536.0 * 2 * M_PI;
  const double start = env.angle();
  ASSERT_TRUE(env.Step({0.0}, absl::MakeSpan(observation)).ok());
  EXPECT_NEAR(std::remainder(env.angle() - start, 2 * M_PI), 4 * slow, 1e-12);
  ASSERT_TRUE(env.Step({0.0}, absl::MakeSpan(observation)).ok());
  EXPECT_NEAR(std::remainder(env.angle() - start, 2 * M_PI),
              5 * slow + 3 * fast, 1e-12);
  // Either turn key keeps the count going (G_BuildTiccmd), so turning
  // back is fast at once.
  ASSERT_TRUE(env.Step({1.0}, absl::MakeSpan(observation)).ok());
  EXPECT_NEAR(std::remainder(env.angle() - start, 2 * M_PI),
              5 * slow + 3 * fast - 4 * fast, 1e-12);

  // Walk east across the first room, north of its doorway: thrust 25/32
  // units per tic, friction 0xE800/65536 after each move.
  const std::string blob = *env.SaveState();
  StateWriter writer("first_person_maze", 1);
  writer.PutBool(false);
  writer.PutDoubles({1.5, 16.5, 0.0, 0.0, 0.0});
  writer.PutI64(0);
  ASSERT_TRUE(env.RestoreState(std::move(writer).Finish()).ok()) << blob.size();
  const double thrust = 25.0 / 32.0 / 64.0;
  const double friction = 0xE800 / 65536.0;
  double speed = 0.0;
  double expected = 1.5;
  for (int step = 0; step < 3; ++step) {
    ASSERT_TRUE(env.Step({2.0}, absl::MakeSpan(observation)).ok());
    for (int tic = 0; tic < 4; ++tic) {
      speed += thrust;
      expected += speed;
      speed *= friction;
    }
    EXPECT_NEAR(env.x(), expected, 1e-12);
    EXPECT_EQ(env.y(), 16.5);
  }
  // Top speed thrust / (1 - friction) = 8.33 units per tic; the room's
  // east wall (at x = 6, minus the 16-unit radius) stops the walk.
  for (int step = 0; step < 40; ++step) {
    ASSERT_TRUE(env.Step({2.0}, absl::MakeSpan(observation)).ok());
  }
  EXPECT_NEAR(env.x(), 6.0 - 0.25, 0.14);
  EXPECT_LT(env.x(), 6.0 - 0.25);
}

// Follows the shortest path's cell centres: turns until roughly facing the
// next one, walks otherwise.
TEST(FirstPersonMazeTest, FollowingTheWayFromEveryStartReachesTheGoal) {
  std::map<std::pair<int, int>, bool> starts;
  for (uint64_t seed = 0; seed < 40; ++seed) {
    FirstPersonMaze env;
    std::vector<double> observation(kObservation);
    ASSERT_TRUE(env.Reset(seed, absl::MakeSpan(observation)).ok());
    starts[{static_cast<int>(env.x()) / 6, static_cast<int>(env.y()) / 6}] =
        true;
    double total = 0.0;
    int steps = 0;
    bool reached = false;
    while (steps < 525 && !reached) {
      const std::vector<Cell> path =
          PathToGoal({static_cast<int>(env.x()), static_cast<int>(env.y())});
      ASSERT_FALSE(path.empty());
      const Cell next = path[std::min<size_t>(1, path.size() - 1)];
      const double heading =
          std::atan2(next.second + 0.5 - env.y(), next.first + 0.5 - env.x());
      const double error = std::remainder(heading - env.angle(), 2 * M_PI);
      const double action = std::abs(error) < 0.35 ? 2.0
                            : error > 0            ? 0.0
                                                   : 1.0;
      absl::StatusOr<StepResult> step =
          env.Step({action}, absl::MakeSpan(observation));
      ASSERT_TRUE(step.ok()) << step.status();
      total += step->reward;
      ++steps;
      reached = step->terminated;
    }
    ASSERT_TRUE(reached) << "seed " << seed << " at " << env.x() << ","
                         << env.y();
    // +1 less 0.0001 per tic.
    EXPECT_GT(total, 1.0 - 0.0001 * 4 * steps - 1e-9);
    EXPECT_LE(total, 1.0 - 0.0001 * (4 * steps - 3) + 1e-9);
    // Standing at the goal: the next call needs a reset.
    EXPECT_EQ(env.Step({2.0}, absl::MakeSpan(observation)).status().code(),
              absl::StatusCode::kFailedPrecondition);
  }
  EXPECT_EQ(starts.size(), 7u);
}

TEST(FirstPersonMazeTest, ARandomWalkRarelyFindsTheGoal) {
  int found = 0;
  for (uint64_t seed = 0; seed < 20; ++seed) {
    FirstPersonMaze env;
    std::vector<double> observation(kObservation);
    ASSERT_TRUE(env.Reset(seed, absl::MakeSpan(observation)).ok());
    std::mt19937_64 random(seed);
    for (int t = 0; t < 525; ++t) {
      absl::StatusOr<StepResult> step =
          env.Step({static_cast<double>(
                       std::uniform_int_distribution<int>(0, 3)(random))},
                   absl::MakeSpan(observation));
      ASSERT_TRUE(step.ok());
      if (step->terminated) {
        ++found;
        break;
      }
    }
  }
  EXPECT_LE(found, 2);
}

TEST(FirstPersonMazeTest, ObservationsArePicturesOfTheView) {
  FirstPersonMaze env;
  std::vector<double> observation(kObservation);
  ASSERT_TRUE(env.Reset(3, absl::MakeSpan(observation)).ok());
  absl::StatusOr<Frame> frame = env.Render(42, 42);
  ASSERT_TRUE(frame.ok());
  // Channel-major observation, row-major picture: the same pixels.
  for (int i = 0; i < 42 * 42; ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(observation[c * 42 * 42 + i], frame->rgb[3 * i + c]);
    }
  }
  EXPECT_FALSE(env.Render(0, 10).ok());
}

std::string State(bool needs_reset, std::vector<double> pose, int64_t held) {
  StateWriter writer("first_person_maze", 1);
  writer.PutBool(needs_reset);
  writer.PutDoubles(pose);
  writer.PutI64(held);
  return std::move(writer).Finish();
}

TEST(FirstPersonMazeTest, HostileStatesAreRefusedAndChangeNothing) {
  FirstPersonMaze fresh;
  FirstPersonMaze copy;
  const absl::Status fresh_restored = copy.RestoreState(*fresh.SaveState());
  EXPECT_TRUE(fresh_restored.ok()) << fresh_restored;
  FirstPersonMaze env;
  std::vector<double> observation(kObservation);
  ASSERT_TRUE(env.Reset(5, absl::MakeSpan(observation)).ok());
  const std::string before = *env.SaveState();
  const std::vector<std::pair<std::string, std::string>> hostile = {
      {State(false, {0.5, 1.5, 0, 0, 0}, 0), "would overlap a wall"},
      {State(false, {100.0, 15.5, 0, 0, 0}, 0), "outside the map"},
      {State(false, {2147483647.9, 15.5, 0, 0, 0}, 0), "outside the map"},
      {State(false, {3.5, std::nan(""), 0, 0, 0}, 0), "non-finite"},
      {State(false, {3.5, 15.5, 7.0, 0, 0}, 0), "not in [-pi, pi]"},
      {State(false, {3.5, 15.5, 0, 2.0, 0}, 0), "above Doom's limit"},
      {State(false, {3.5, 15.5, 0, 0, 0}, 9), "turn_held 9"},
      {"junk", "saved state"}};
  for (const auto& [blob, message] : hostile) {
    const absl::Status status = env.RestoreState(blob);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << message;
    EXPECT_THAT(status.message(), HasSubstr(message));
    EXPECT_EQ(*env.SaveState(), before);
  }
}

}  // namespace
}  // namespace vantage
