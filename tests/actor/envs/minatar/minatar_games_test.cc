#include <algorithm>
#include <array>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "actor/envs/env_registry.h"
#include "actor/envs/minatar/asterix.h"
#include "actor/envs/minatar/breakout.h"
#include "actor/envs/minatar/freeway.h"
#include "actor/envs/minatar/minatar_env.h"
#include "actor/envs/minatar/seaquest.h"
#include "actor/envs/minatar/space_invaders.h"
#include "common/util/state_bytes.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;
using A = MinAtarAction;

std::vector<uint8_t> Grid(const MinAtarGame& game) {
  std::vector<uint8_t> grid(game.channels() * kMinAtarCells);
  game.Observe(absl::MakeSpan(grid));
  return grid;
}

// The cells (y, x) set in one channel.
std::vector<std::pair<int, int>> Cells(const MinAtarGame& game, int channel) {
  const std::vector<uint8_t> grid = Grid(game);
  std::vector<std::pair<int, int>> cells;
  for (int y = 0; y < kMinAtarGridSize; ++y) {
    for (int x = 0; x < kMinAtarGridSize; ++x) {
      if (grid[Cell(channel, y, x)]) cells.emplace_back(y, x);
    }
  }
  return cells;
}

int Count(const MinAtarGame& game, int channel) {
  return static_cast<int>(Cells(game, channel).size());
}

// Breakout: a paddle that follows the ball never misses it; one that stays
// put soon does.
TEST(BreakoutTest, APaddleTrackingTheBallKeepsItInPlayAndClearsTheBricks) {
  for (uint64_t seed : {1, 2, 3}) {
    Breakout game;
    std::mt19937_64 random(seed);
    game.Reset(random);
    ASSERT_EQ(game.bricks(), 30);
    ASSERT_EQ(game.ball_y(), 3);
    ASSERT_TRUE(game.ball_x() == 0 || game.ball_x() == 9);
    double score = 0.0;
    for (int t = 0; t < 3000; ++t) {
      // Under the ball: it bounces back up with its sideways direction
      // kept, so it sweeps the wall instead of retracing its path.
      const int target = game.ball_x();
      const A action = target < game.paddle()   ? A::kLeft
                       : target > game.paddle() ? A::kRight
                                                : A::kNoop;
      const GameStep step = game.Act(action, random);
      ASSERT_FALSE(step.terminal) << "seed " << seed << " step " << t;
      ASSERT_LE(step.reward, 1.0);
      score += step.reward;
      // The observation shows what the game holds.
      ASSERT_EQ(
          Cells(game, 1),
          (std::vector<std::pair<int, int>>{{game.ball_y(), game.ball_x()}}));
      ASSERT_EQ(Cells(game, 0),
                (std::vector<std::pair<int, int>>{{9, game.paddle()}}));
      ASSERT_EQ(Count(game, 3), game.bricks());
    }
    // More than one wall of bricks: the wall came back once cleared.
    EXPECT_GT(score, 30.0) << "seed " << seed;
  }
}

// MinAtar's two paddle hits: under the ball's column the ball's vertical
// direction flips; under the column it is about to enter (the paddle moved
// there this step) the ball goes back the way it came. The paddle leads
// the falling ball by a column to make the second.
TEST(BreakoutTest, APaddleUnderTheBallsNextColumnSendsItBack) {
  constexpr int kReverse[4] = {2, 3, 0, 1};
  int diagonal_hits = 0;
  for (uint64_t seed : {1, 2, 3, 4}) {
    Breakout game;
    std::mt19937_64 random(seed);
    game.Reset(random);
    for (int t = 0; t < 400; ++t) {
      const int direction = game.ball_direction();
      const int step_x = direction == 1 || direction == 2 ? 1 : -1;
      const int next_x = game.ball_x() + step_x;
      const bool falling = direction == 2 || direction == 3;
      const bool leads = falling && game.ball_y() >= 7 && next_x >= 0 &&
                         next_x < kMinAtarGridSize;
      const int target = leads ? next_x : game.ball_x();
      const A action = target < game.paddle()   ? A::kLeft
                       : target > game.paddle() ? A::kRight
                                                : A::kNoop;
      const bool diagonal =
          leads && game.ball_y() == 8 && std::abs(game.paddle() - next_x) <= 1;
      const GameStep step = game.Act(action, random);
      ASSERT_FALSE(step.terminal) << "seed " << seed << " step " << t;
      if (diagonal) {
        ASSERT_EQ(game.paddle(), next_x);
        EXPECT_EQ(game.ball_x(), next_x);
        EXPECT_EQ(game.ball_y(), 8);
        EXPECT_EQ(game.ball_direction(), kReverse[direction]);
        ++diagonal_hits;
      }
    }
  }
  EXPECT_GT(diagonal_hits, 10);
}

TEST(BreakoutTest, AStillPaddleLosesTheBallAndTheGameStaysOver) {
  Breakout game;
  std::mt19937_64 random(4);
  game.Reset(random);
  int steps = 0;
  GameStep step;
  while (!step.terminal && steps < 1000) {
    step = game.Act(A::kNoop, random);
    ++steps;
  }
  ASSERT_TRUE(step.terminal);
  EXPECT_LT(steps, 200);
  EXPECT_EQ(game.ball_y(), 9);  // drawn where it fell
  const std::vector<uint8_t> before = Grid(game);
  const GameStep after = game.Act(A::kLeft, random);
  EXPECT_TRUE(after.terminal);
  EXPECT_EQ(after.reward, 0.0);
  EXPECT_EQ(Grid(game), before);
}

TEST(FreewayTest, AlwaysUpCrossesAndScoresUntilTheTimeLimit) {
  Freeway game;
  std::mt19937_64 random(5);
  game.Reset(random);
  ASSERT_EQ(game.chicken(), 9);
  for (const Freeway::Car& car : game.cars()) {
    ASSERT_GE(std::abs(car.speed), 1);
    ASSERT_LE(std::abs(car.speed), 5);
  }
  double score = 0.0;
  int steps = 0;
  GameStep step;
  while (!step.terminal) {
    step = game.Act(A::kUp, random);
    score += step.reward;
    ++steps;
    ASSERT_EQ(Cells(game, 0),
              (std::vector<std::pair<int, int>>{{game.chicken(), 4}}));
    ASSERT_EQ(Count(game, 1), 8);
    // One trail per car, in the channel of its speed.
    int trails = 0;
    for (int c = 2; c < 7; ++c) trails += Count(game, c);
    ASSERT_EQ(trails, 8);
  }
  EXPECT_EQ(steps, 2501);
  // A crossing needs 27 steps with no car in the way (one row per 3).
  EXPECT_GE(score, 10.0);
  EXPECT_LE(score, 2501.0 / 27.0);
}

TEST(FreewayTest, StandingStillNeverScores) {
  Freeway game;
  std::mt19937_64 random(6);
  game.Reset(random);
  double score = 0.0;
  for (int t = 0; t < 2501; ++t) score += game.Act(A::kNoop, random).reward;
  EXPECT_EQ(score, 0.0);
  EXPECT_EQ(game.chicken(), 9);
}

TEST(SpaceInvadersTest, TheBlockMovesOnItsTimerAndAStillCannonIsShot) {
  SpaceInvaders game(/*ramping=*/true);
  std::mt19937_64 random(7);
  game.Reset(random);
  ASSERT_EQ(game.aliens(), 24);
  // The block (columns 2-7) first moves left on step 13.
  const auto leftmost = [&] { return Cells(game, 1).front().second; };
  for (int t = 1; t <= 12; ++t) {
    game.Act(A::kNoop, random);
    ASSERT_EQ(leftmost(), 2) << "step " << t;
  }
  game.Act(A::kNoop, random);
  EXPECT_EQ(leftmost(), 1);
  EXPECT_EQ(Count(game, 2), 24);  // alien_left: the block heads left
  EXPECT_EQ(Count(game, 3), 0);
  // The alien nearest the cannon fired on step 11; its bullet falls a row
  // a step and hits the cannon standing under it.
  GameStep step;
  int t = 13;
  while (!step.terminal && t < 100) {
    step = game.Act(A::kNoop, random);
    ++t;
  }
  EXPECT_TRUE(step.terminal);
  EXPECT_LT(t, 30);
}

TEST(SpaceInvadersTest, FiringClearsWavesWhichThenComeFaster) {
  SpaceInvaders game(/*ramping=*/true);
  std::mt19937_64 random(8);
  game.Reset(random);
  double score = 0.0;
  int t = 0;
  GameStep step;
  // Fire whenever the cannon can, step aside from falling bullets, and
  // otherwise go under the nearest column of aliens.
  const auto threatened = [&](const std::vector<uint8_t>& grid, int x) {
    for (int y = 2; y < 10; ++y) {
      if (grid[Cell(5, y, x)]) return true;
    }
    return false;
  };
  while (!step.terminal && t < 5000 && game.move_interval() == 12) {
    const std::vector<uint8_t> grid = Grid(game);
    const int cannon = game.cannon();
    int best = -1;
    for (const auto& [y, x] : Cells(game, 1)) {
      if (best < 0 || std::abs(x - cannon) < std::abs(best - cannon)) best = x;
    }
    A action = A::kFire;
    if (threatened(grid, cannon)) {
      const bool left_ok = cannon > 0 && !threatened(grid, cannon - 1);
      const bool right_ok = cannon < 9 && !threatened(grid, cannon + 1);
      if (left_ok && (!right_ok || best < cannon)) {
        action = A::kLeft;
      } else if (right_ok) {
        action = A::kRight;
      }
    } else if (best != cannon && Count(game, 4) > 0) {
      // A shot is on its way: use the cool-down to line up the next.
      const int next = best < cannon ? cannon - 1 : cannon + 1;
      if (!threatened(grid, next))
        action = best < cannon ? A::kLeft : A::kRight;
    }
    step = game.Act(action, random);
    score += step.reward;
    ++t;
  }
  EXPECT_GE(score, 24.0) << "steps " << t;
  EXPECT_EQ(game.move_interval(), 11);
}

// Cars move every |speed| + 1 steps (MinAtar's timer re-arms to |speed|
// and counts down through 0), each in its own direction, wrapping round.
TEST(FreewayTest, ACarMovesEverySpeedPlusOneSteps) {
  Freeway game;
  std::mt19937_64 random(12);
  game.Reset(random);
  const std::array<Freeway::Car, 8> start = game.cars();
  std::array<int, 8> moves{};
  std::array<int, 8> last_move{};
  for (int t = 1; t <= 60; ++t) {
    const std::array<Freeway::Car, 8> before = game.cars();
    game.Act(A::kNoop, random);
    for (int i = 0; i < 8; ++i) {
      const Freeway::Car& car = game.cars()[i];
      if (car.x == before[i].x) continue;
      const int step = car.speed > 0 ? 1 : -1;
      ASSERT_EQ((before[i].x + step + 10) % 10, car.x) << "car " << i;
      if (moves[i] > 0) {
        EXPECT_EQ(t - last_move[i], std::abs(car.speed) + 1) << "car " << i;
      }
      ++moves[i];
      last_move[i] = t;
    }
  }
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(game.cars()[i].speed, start[i].speed);  // no crossing
    EXPECT_GE(moves[i], 60 / (std::abs(start[i].speed) + 1) - 1);
  }
}

// The alien nearest the cannon's column fires from the lowest alien of
// that column, on step 11.
TEST(SpaceInvadersTest, TheLowestAlienOfTheNearestColumnFires) {
  SpaceInvaders game(/*ramping=*/true);
  std::mt19937_64 random(13);
  game.Reset(random);
  for (int t = 1; t <= 11; ++t) {
    // To the right edge: the nearest aliens are then in column 7.
    game.Act(t <= 4 ? A::kRight : A::kNoop, random);
    if (t < 11) ASSERT_TRUE(Cells(game, 5).empty()) << t;
  }
  ASSERT_EQ(game.cannon(), 9);
  EXPECT_EQ(Cells(game, 5), (std::vector<std::pair<int, int>>{{3, 7}}));
}

// With ramping, spawns first speed up on step 102 (from every 10 steps to
// every 9); moves only from the second ramp on.
TEST(AsterixTest, TheFirstRampComesOnStep102) {
  int checked = 0;
  for (uint64_t seed = 0; seed < 50 && checked == 0; ++seed) {
    Asterix game(/*ramping=*/true);
    std::mt19937_64 random(seed);
    game.Reset(random);
    bool alive = true;
    for (int t = 1; t <= 102 && alive; ++t) {
      const Asterix::Entity& lane = game.lanes()[game.player_y() - 1];
      const A action = lane.present && !lane.gold
                           ? (game.player_y() > 1 ? A::kUp : A::kDown)
                           : A::kNoop;
      alive = !game.Act(action, random).terminal;
      if (alive && t == 101) {
        ASSERT_EQ(game.spawn_interval(), 10);
      }
    }
    if (!alive) continue;
    EXPECT_EQ(game.spawn_interval(), 9);
    EXPECT_EQ(game.move_interval(), 5);
    ++checked;
  }
  EXPECT_EQ(checked, 1);
}

TEST(SeaquestTest, OxygenDrainsBelowAndSurfacingWithoutDiversEndsTheGame) {
  Seaquest game(/*ramping=*/true);
  std::mt19937_64 random(9);
  game.Reset(random);
  // At the surface nothing is used and nothing ends.
  for (int t = 0; t < 10; ++t)
    ASSERT_FALSE(game.Act(A::kNoop, random).terminal);
  EXPECT_EQ(game.oxygen(), 200);
  EXPECT_EQ(Count(game, 7), 10);  // full gauge
  ASSERT_FALSE(game.Act(A::kDown, random).terminal);
  EXPECT_EQ(game.sub_y(), 1);
  EXPECT_EQ(game.oxygen(), 199);
  EXPECT_EQ(Count(game, 7), 9);
  // Front and back of the sub, facing left as it starts.
  EXPECT_EQ(Cells(game, 0), (std::vector<std::pair<int, int>>{{1, 5}}));
  EXPECT_EQ(Cells(game, 1), (std::vector<std::pair<int, int>>{{1, 6}}));
  const GameStep up = game.Act(A::kUp, random);
  EXPECT_TRUE(up.terminal);
  EXPECT_EQ(up.reward, 0.0);
}

TEST(SeaquestTest, ShootingScoresAndOxygenRunsOut) {
  // Down one row, then fire in both directions in turn: enemies crossing
  // that row score until the oxygen (200 steps) or an enemy ends it.
  double best = 0.0;
  int longest = 0;
  for (uint64_t seed = 0; seed < 20; ++seed) {
    Seaquest game(/*ramping=*/true);
    std::mt19937_64 random(seed);
    game.Reset(random);
    double score = 0.0;
    int t = 0;
    GameStep step = game.Act(A::kDown, random);
    while (!step.terminal) {
      const A action = t % 10 == 0   ? A::kLeft
                       : t % 10 == 5 ? A::kRight
                                     : A::kFire;
      step = game.Act(action, random);
      score += step.reward;
      ++t;
      // Down to -1 on the step that finds it empty.
      ASSERT_EQ(game.oxygen(), 199 - t);
      ASSERT_LE(t, 200);
    }
    best = std::max(best, score);
    longest = std::max(longest, t + 1);
  }
  EXPECT_GE(best, 3.0);
  // Some run lasted until the oxygen ran out: 200 steps below, then the
  // step that finds it empty.
  EXPECT_EQ(longest, 201);
}

TEST(AsterixTest, GoldScoresEnemiesEndAndTheGameSpeedsUp) {
  int ramped = 0;
  double best = 0.0;
  for (uint64_t seed = 0; seed < 50; ++seed) {
    Asterix game(/*ramping=*/true);
    std::mt19937_64 random(seed);
    game.Reset(random);
    EXPECT_EQ(Cells(game, 0), (std::vector<std::pair<int, int>>{{5, 5}}));
    double score = 0.0;
    int t = 0;
    GameStep step;
    while (!step.terminal && t < 1000) {
      // Stay in a lane that is empty, or holds gold, else move away.
      const auto& lanes = game.lanes();
      const auto safe = [&](int row) {
        const Asterix::Entity& e = lanes[row - 1];
        return !e.present || e.gold;
      };
      A action = A::kNoop;
      if (!safe(game.player_y())) {
        action = game.player_y() > 1 && safe(game.player_y() - 1) ? A::kUp
                                                                  : A::kDown;
      }
      step = game.Act(action, random);
      score += step.reward;
      ++t;
      // Entities live in rows 1-8, one per lane, gold apart from enemies.
      ASSERT_EQ(
          Count(game, 1) + Count(game, 3),
          std::count_if(lanes.begin(), lanes.end(),
                        [](const Asterix::Entity& e) { return e.present; }));
    }
    best = std::max(best, score);
    if (t > 204) {
      ++ramped;
      // Ramped twice by step 204: spawns every 8 steps, moves every 4.
      EXPECT_LE(game.spawn_interval(), 8);
      EXPECT_LE(game.move_interval(), 4);
    }
  }
  EXPECT_GT(ramped, 0);
  EXPECT_GE(best, 5.0);
}

std::unique_ptr<Environment> MakeEnv(const std::string& name) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? std::move(*env) : nullptr;
}

TEST(MinAtarEnvTest, SpecsAndObservations) {
  const std::vector<std::pair<std::string, int>> channels = {
      {"MinAtarBreakout", 4},
      {"MinAtarSpaceInvaders", 6},
      {"MinAtarFreeway", 7},
      {"MinAtarSeaquest", 10},
      {"MinAtarAsterix", 4}};
  for (const auto& [name, c] : channels) {
    const auto env = MakeEnv(name);
    ASSERT_NE(env, nullptr);
    const EnvSpec& spec = env->spec();
    EXPECT_EQ(spec.observation_size, c * 100) << name;
    EXPECT_TRUE(spec.discrete);
    EXPECT_EQ(spec.action_size, 6);
    std::vector<double> observation(spec.observation_size);
    ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
    for (double v : observation) ASSERT_TRUE(v == 0.0 || v == 1.0) << name;
    absl::StatusOr<StepResult> bad =
        env->Step({6.0}, absl::MakeSpan(observation));
    EXPECT_THAT(bad.status().message(), HasSubstr("not an integer in [0, 6)"));
    absl::StatusOr<Frame> frame = env->Render(40, 30);
    ASSERT_TRUE(frame.ok()) << frame.status();
    EXPECT_EQ(frame->rgb.size(), 40u * 30u * 3u);
  }
}

// With probability 0.1 the previous action is played instead of the one
// chosen. Alternating left and right, the paddle shows what was played;
// on the steps whose choice differs from what the previous step played,
// the paddle repeats that move exactly when the draw says so.
TEST(MinAtarEnvTest, StickyActionsRepeatThePreviousActionOneTimeInTen) {
  const auto env = MakeEnv("MinAtarBreakout");
  std::vector<double> observation(400);
  int observed = 0;
  int repeated = 0;
  uint64_t seed = 100;
  ASSERT_TRUE(env->Reset(seed, absl::MakeSpan(observation)).ok());
  const auto paddle = [&] {
    for (int x = 0; x < 10; ++x) {
      if (observation[Cell(0, 9, x)] != 0.0) return x;
    }
    return -1;
  };
  // The previous step's move: +1, -1, or 0 (unknown: a wall, a reset, or
  // the noop a new episode starts with).
  int previous = 0;
  for (int t = 0; observed < 20000; ++t) {
    const int before = paddle();
    const int chosen = t % 2 == 0 ? 1 : -1;
    absl::StatusOr<StepResult> step =
        env->Step({chosen > 0 ? 3.0 : 1.0}, absl::MakeSpan(observation));
    ASSERT_TRUE(step.ok()) << step.status();
    if (step->terminated || step->truncated) {
      ASSERT_TRUE(env->Reset(++seed, absl::MakeSpan(observation)).ok());
      previous = 0;
      t = -1;
      continue;
    }
    const int moved = paddle() - before;
    const bool seen = before > 0 && before < 9;
    if (seen && previous != 0 && previous != chosen) {
      ++observed;
      ASSERT_TRUE(moved == 1 || moved == -1) << moved;
      if (moved == previous) ++repeated;
    }
    previous = seen ? moved : 0;
  }
  const double fraction = static_cast<double>(repeated) / observed;
  EXPECT_NEAR(fraction, 0.1, 0.007);
}

std::string MinAtarState(const std::string& name, bool needs_reset,
                         uint64_t seed, const std::string& actions,
                         uint64_t fingerprint) {
  StateWriter writer("minatar_env", 1);
  writer.PutBytes(name);
  writer.PutBool(needs_reset);
  writer.PutU64(seed);
  writer.PutBytes(actions);
  writer.PutU64(fingerprint);
  return std::move(writer).Finish();
}

TEST(MinAtarEnvTest, AStateSavedBeforeAnyEpisodeRestores) {
  for (const std::string& name : {"MinAtarBreakout", "MinAtarSeaquest"}) {
    const auto fresh = MakeEnv(name);
    const auto other = MakeEnv(name);
    absl::StatusOr<std::string> state = fresh->SaveState();
    ASSERT_TRUE(state.ok()) << state.status();
    const absl::Status restored = other->RestoreState(*state);
    EXPECT_TRUE(restored.ok()) << name << ": " << restored;
    EXPECT_EQ(*other->SaveState(), *state) << name;
  }
  absl::StatusOr<std::unique_ptr<Environment>> inner = MakeMinAtarBreakout();
  absl::StatusOr<std::unique_ptr<Environment>> copy = MakeMinAtarBreakout();
  const std::string inner_state = *(*inner)->SaveState();
  const absl::Status restored = (*copy)->RestoreState(inner_state);
  EXPECT_TRUE(restored.ok()) << restored;
  EXPECT_EQ(*(*copy)->SaveState(), inner_state);
}

// Without the TimeLimit wrapper too: a sub idling at the surface is never
// hit, and its episode is truncated on step 10,000, restorably.
TEST(MinAtarEnvTest, EpisodesStopAtTheirLimitUnwrapped) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeMinAtarSeaquest();
  ASSERT_TRUE(env.ok());
  std::vector<double> observation(1000);
  ASSERT_TRUE((*env)->Reset(1, absl::MakeSpan(observation)).ok());
  for (int t = 0; t < 10000; ++t) {
    absl::StatusOr<StepResult> step =
        (*env)->Step({0.0}, absl::MakeSpan(observation));
    ASSERT_TRUE(step.ok()) << t << ": " << step.status();
    ASSERT_FALSE(step->terminated);
    ASSERT_EQ(step->truncated, t == 9999);
  }
  EXPECT_EQ((*env)->Step({0.0}, absl::MakeSpan(observation)).status().code(),
            absl::StatusCode::kFailedPrecondition);
  absl::StatusOr<std::unique_ptr<Environment>> copy = MakeMinAtarSeaquest();
  const std::string state = *(*env)->SaveState();
  const absl::Status restored = (*copy)->RestoreState(state);
  EXPECT_TRUE(restored.ok()) << restored;
  EXPECT_EQ(*(*copy)->SaveState(), state);
}

TEST(MinAtarEnvTest, StatesReplayExactlyAndHostileOnesChangeNothing) {
  absl::StatusOr<std::unique_ptr<Environment>> made = MakeMinAtarSeaquest();
  ASSERT_TRUE(made.ok());
  Environment& env = **made;
  std::vector<double> observation(1000);
  ASSERT_TRUE(env.Reset(3, absl::MakeSpan(observation)).ok());
  for (int t = 0; t < 30; ++t) {
    ASSERT_TRUE(
        env.Step({t % 3 == 0 ? 4.0 : 5.0}, absl::MakeSpan(observation)).ok());
  }
  absl::StatusOr<std::string> saved = env.SaveState();
  ASSERT_TRUE(saved.ok()) << saved.status();

  absl::StatusOr<std::unique_ptr<Environment>> other = MakeMinAtarSeaquest();
  ASSERT_TRUE(other.ok());
  // Read the saved fields back to craft variants of the blob.
  StateReader reader(*saved, "minatar_env", 1, "test");
  reader.GetBytes("name");
  reader.GetBool("needs_reset");
  const uint64_t seed = reader.GetU64("seed");
  const std::string actions(reader.GetBytes("actions"));
  const uint64_t fingerprint = reader.GetU64("fingerprint");
  ASSERT_TRUE(reader.Finish().ok());
  ASSERT_EQ(actions.size(), 30u);

  std::string bad_action = actions;
  bad_action[7] = 9;
  const std::vector<std::pair<std::string, std::string>> hostile = {
      {MinAtarState("MinAtarSeaquest", false, seed, bad_action, fingerprint),
       "action 9 is not in [0, 6)"},
      {MinAtarState("MinAtarSeaquest", false, seed + 1, actions, fingerprint),
       "does not give the saved game"},
      {MinAtarState("MinAtarSeaquest", false, seed, std::string(10001, 0),
                    fingerprint),
       "10001 actions"},
      {MinAtarState("MinAtarSeaquest", true, seed, actions, fingerprint),
       "do not end the game"},
      {MinAtarState("MinAtarBreakout", false, seed, actions, fingerprint),
       "MinAtarBreakout"},
      {"not a state", "MinAtar state"}};
  std::vector<double> before(1000);
  ASSERT_TRUE((*other)->Reset(8, absl::MakeSpan(before)).ok());
  const absl::StatusOr<std::string> other_state = (*other)->SaveState();
  for (const auto& [blob, message] : hostile) {
    const absl::Status status = (*other)->RestoreState(blob);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << message;
    EXPECT_THAT(status.message(), HasSubstr(message));
    EXPECT_EQ(*(*other)->SaveState(), *other_state) << message;
  }

  ASSERT_TRUE((*other)->RestoreState(*saved).ok());
  EXPECT_EQ(*(*other)->SaveState(), *saved);
  std::vector<double> a(1000), b(1000);
  for (int t = 0; t < 300; ++t) {
    absl::StatusOr<StepResult> x =
        env.Step({t % 2 ? 1.0 : 5.0}, absl::MakeSpan(a));
    absl::StatusOr<StepResult> y =
        (*other)->Step({t % 2 ? 1.0 : 5.0}, absl::MakeSpan(b));
    ASSERT_EQ(x.ok(), y.ok());
    if (!x.ok()) break;
    ASSERT_EQ(a, b);
    ASSERT_EQ(x->reward, y->reward);
    ASSERT_EQ(x->terminated, y->terminated);
    if (x->terminated) break;
  }
}

}  // namespace
}  // namespace vantage
