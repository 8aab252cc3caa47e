#include "actor/envs/minatar/asterix.h"

#include <algorithm>
#include <vector>

namespace vantage {
namespace {

constexpr int kRampInterval = 100;
constexpr int kInitialSpawnInterval = 10;
constexpr int kInitialMoveInterval = 5;
constexpr int kRight = kMinAtarGridSize - 1;

}  // namespace

void Asterix::Reset(std::mt19937_64&) {
  player_x_ = 5;
  player_y_ = 5;
  lanes_.fill(Entity{});
  spawn_speed_ = kInitialSpawnInterval;
  spawn_timer_ = spawn_speed_;
  move_speed_ = kInitialMoveInterval;
  move_timer_ = move_speed_;
  ramp_timer_ = kRampInterval;
  ramp_index_ = 0;
  terminal_ = false;
}

void Asterix::Spawn(std::mt19937_64& random) {
  // Direction and kind are drawn even when no lane is free.
  const bool moves_right = UniformUnit(random) < 0.5;
  const bool gold = UniformUnit(random) < 1.0 / 3.0;
  std::vector<int> free;
  for (int i = 0; i < static_cast<int>(lanes_.size()); ++i) {
    if (!lanes_[i].present) free.push_back(i);
  }
  if (free.empty()) return;
  const int lane = free[UniformBelow(random, static_cast<int>(free.size()))];
  lanes_[lane] = Entity{true, moves_right ? 0 : kRight, moves_right, gold};
}

void Asterix::Touch(Entity& entity, GameStep& step) {
  if (entity.gold) {
    entity.present = false;
    step.reward += 1.0;
  } else {
    terminal_ = true;
  }
}

GameStep Asterix::Act(MinAtarAction action, std::mt19937_64& random) {
  GameStep step;
  if (terminal_) {
    step.terminal = true;
    return step;
  }
  if (spawn_timer_ == 0) {
    Spawn(random);
    spawn_timer_ = spawn_speed_;
  }
  switch (action) {
    case MinAtarAction::kLeft:
      player_x_ = std::max(0, player_x_ - 1);
      break;
    case MinAtarAction::kRight:
      player_x_ = std::min(kRight, player_x_ + 1);
      break;
    case MinAtarAction::kUp:
      player_y_ = std::max(1, player_y_ - 1);
      break;
    case MinAtarAction::kDown:
      player_y_ = std::min(8, player_y_ + 1);
      break;
    default:
      break;
  }
  for (int i = 0; i < static_cast<int>(lanes_.size()); ++i) {
    Entity& entity = lanes_[i];
    if (entity.present && entity.x == player_x_ && i + 1 == player_y_) {
      Touch(entity, step);
    }
  }
  if (move_timer_ == 0) {
    move_timer_ = move_speed_;
    for (int i = 0; i < static_cast<int>(lanes_.size()); ++i) {
      Entity& entity = lanes_[i];
      if (!entity.present) continue;
      entity.x += entity.moves_right ? 1 : -1;
      if (!OnGrid(entity.x)) {
        entity.present = false;
      } else if (entity.x == player_x_ && i + 1 == player_y_) {
        Touch(entity, step);
      }
    }
  }
  --spawn_timer_;
  --move_timer_;
  if (ramping_ && (spawn_speed_ > 1 || move_speed_ > 1)) {
    if (ramp_timer_ >= 0) {
      --ramp_timer_;
    } else {
      if (move_speed_ > 1 && ramp_index_ % 2 == 1) --move_speed_;
      if (spawn_speed_ > 1) --spawn_speed_;
      ++ramp_index_;
      ramp_timer_ = kRampInterval;
    }
  }
  step.terminal = terminal_;
  return step;
}

void Asterix::Observe(absl::Span<uint8_t> grid) const {
  std::fill(grid.begin(), grid.end(), 0);
  grid[Cell(0, player_y_, player_x_)] = 1;
  for (int i = 0; i < static_cast<int>(lanes_.size()); ++i) {
    const Entity& entity = lanes_[i];
    if (!entity.present) continue;
    grid[Cell(entity.gold ? 3 : 1, i + 1, entity.x)] = 1;
    const int back_x = entity.moves_right ? entity.x - 1 : entity.x + 1;
    if (OnGrid(back_x)) grid[Cell(2, i + 1, back_x)] = 1;
  }
}

}  // namespace vantage
