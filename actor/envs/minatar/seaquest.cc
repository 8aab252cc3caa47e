#include "actor/envs/minatar/seaquest.h"

#include <algorithm>

namespace vantage {
namespace {

constexpr int kMaxOxygen = 200;
constexpr int kInitialSpawnInterval = 20;
constexpr int kDiverSpawnInterval = 30;
constexpr int kInitialMoveInterval = 5;
constexpr int kShotCoolDown = 5;
constexpr int kEnemyShotInterval = 10;
constexpr int kDiverMoveInterval = 5;
constexpr int kMaxDivers = 6;
constexpr int kRight = kMinAtarGridSize - 1;
constexpr int kDeepest = kMinAtarGridSize - 2;  // row 9 holds the gauges

void Advance(Seaquest::Mover& mover) { mover.x += mover.moves_right ? 1 : -1; }

bool SamePlace(const Seaquest::Mover& a, const Seaquest::Mover& b) {
  return a.x == b.x && a.y == b.y;
}

void DecrementIfPositive(int& timer) {
  if (timer > 0) --timer;
}

}  // namespace

void Seaquest::Reset(std::mt19937_64&) {
  oxygen_ = kMaxOxygen;
  diver_count_ = 0;
  sub_x_ = 5;
  sub_y_ = 0;
  facing_right_ = false;
  f_bullets_.clear();
  e_bullets_.clear();
  fish_.clear();
  subs_.clear();
  divers_.clear();
  enemy_spawn_speed_ = kInitialSpawnInterval;
  enemy_spawn_timer_ = enemy_spawn_speed_;
  diver_spawn_timer_ = kDiverSpawnInterval;
  move_speed_ = kInitialMoveInterval;
  ramp_index_ = 0;
  shot_timer_ = 0;
  surface_ = true;
  terminal_ = false;
}

void Seaquest::SpawnEnemy(std::mt19937_64& random) {
  // All three draws happen even when the spawn is then cancelled, as in
  // MinAtar, so that a cancelled spawn uses the generator like any other.
  Mover enemy;
  enemy.moves_right = UniformUnit(random) < 0.5;
  const bool is_sub = UniformUnit(random) < 1.0 / 3.0;
  enemy.x = enemy.moves_right ? 0 : kRight;
  enemy.y = 1 + UniformBelow(random, 8);
  // No enemy may enter a row that another crosses the other way.
  for (const std::vector<Mover>* list : {&subs_, &fish_}) {
    for (const Mover& other : *list) {
      if (other.y == enemy.y && other.moves_right != enemy.moves_right) return;
    }
  }
  enemy.move_timer = move_speed_;
  if (is_sub) {
    enemy.shot_timer = kEnemyShotInterval;
    subs_.push_back(enemy);
  } else {
    fish_.push_back(enemy);
  }
}

void Seaquest::SpawnDiver(std::mt19937_64& random) {
  Mover diver;
  diver.moves_right = UniformUnit(random) < 0.5;
  diver.x = diver.moves_right ? 0 : kRight;
  diver.y = 1 + UniformBelow(random, 8);
  diver.move_timer = kDiverMoveInterval;
  divers_.push_back(diver);
}

void Seaquest::MoveEnemies(std::vector<Mover>& enemies, bool fire,
                           GameStep& step) {
  for (int i = static_cast<int>(enemies.size()) - 1; i >= 0; --i) {
    // A copy: a sub that is removed below still fires this step (from
    // where it died or just off the grid), as in MinAtar.
    Mover enemy = enemies[i];
    bool removed = false;
    if (AtSub(enemy)) terminal_ = true;
    if (enemy.move_timer == 0) {
      enemy.move_timer = move_speed_;
      Advance(enemy);
      if (!OnGrid(enemy.x)) {
        removed = true;
      } else if (AtSub(enemy)) {
        terminal_ = true;
      } else {
        for (size_t b = 0; b < f_bullets_.size(); ++b) {
          if (SamePlace(enemy, f_bullets_[b])) {
            f_bullets_.erase(f_bullets_.begin() + b);
            removed = true;
            step.reward += 1.0;
            break;
          }
        }
      }
    } else {
      --enemy.move_timer;
    }
    if (fire) {
      if (enemy.shot_timer == 0) {
        enemy.shot_timer = kEnemyShotInterval;
        e_bullets_.push_back(Mover{enemy.x, enemy.y, enemy.moves_right});
      } else {
        --enemy.shot_timer;
      }
    }
    if (removed) {
      enemies.erase(enemies.begin() + i);
    } else {
      enemies[i] = enemy;
    }
  }
}

double Seaquest::Surface() {
  surface_ = true;
  double reward = 0.0;
  if (diver_count_ == kMaxDivers) {
    diver_count_ = 0;
    reward = oxygen_ * 10 / kMaxOxygen;
  }
  oxygen_ = kMaxOxygen;
  // MinAtar also takes this diver after a full load, leaving -1 on board:
  // kept, so the game is the one its published results ran on.
  --diver_count_;
  if (ramping_ && (enemy_spawn_speed_ > 1 || move_speed_ > 2)) {
    if (move_speed_ > 2 && ramp_index_ % 2 == 1) --move_speed_;
    if (enemy_spawn_speed_ > 1) --enemy_spawn_speed_;
    ++ramp_index_;
  }
  return reward;
}

GameStep Seaquest::Act(MinAtarAction action, std::mt19937_64& random) {
  GameStep step;
  if (terminal_) {
    step.terminal = true;
    return step;
  }
  if (enemy_spawn_timer_ == 0) {
    SpawnEnemy(random);
    enemy_spawn_timer_ = enemy_spawn_speed_;
  }
  if (diver_spawn_timer_ == 0) {
    SpawnDiver(random);
    diver_spawn_timer_ = kDiverSpawnInterval;
  }
  MoveSub(action);
  // Newest first throughout, as MinAtar iterates its lists.
  MoveFriendlyBullets(step);
  MoveDivers();
  MoveEnemies(subs_, /*fire=*/true, step);
  MoveEnemyBullets();
  MoveEnemies(fish_, /*fire=*/false, step);
  DecrementIfPositive(enemy_spawn_timer_);
  DecrementIfPositive(diver_spawn_timer_);
  DecrementIfPositive(shot_timer_);
  UseOxygen(step);
  step.terminal = terminal_;
  return step;
}

void Seaquest::MoveSub(MinAtarAction action) {
  if (action == MinAtarAction::kFire && shot_timer_ == 0) {
    f_bullets_.push_back(Mover{sub_x_, sub_y_, facing_right_});
    shot_timer_ = kShotCoolDown;
  } else if (action == MinAtarAction::kLeft) {
    sub_x_ = std::max(0, sub_x_ - 1);
    facing_right_ = false;
  } else if (action == MinAtarAction::kRight) {
    sub_x_ = std::min(kRight, sub_x_ + 1);
    facing_right_ = true;
  } else if (action == MinAtarAction::kUp) {
    sub_y_ = std::max(0, sub_y_ - 1);
  } else if (action == MinAtarAction::kDown) {
    sub_y_ = std::min(kDeepest, sub_y_ + 1);
  }
}

void Seaquest::MoveFriendlyBullets(GameStep& step) {
  for (int i = static_cast<int>(f_bullets_.size()) - 1; i >= 0; --i) {
    Mover& bullet = f_bullets_[i];
    Advance(bullet);
    if (!OnGrid(bullet.x)) {
      f_bullets_.erase(f_bullets_.begin() + i);
      continue;
    }
    for (std::vector<Mover>* targets : {&fish_, &subs_}) {
      auto hit = std::find_if(
          targets->begin(), targets->end(),
          [&](const Mover& target) { return SamePlace(target, bullet); });
      if (hit != targets->end()) {
        targets->erase(hit);
        f_bullets_.erase(f_bullets_.begin() + i);
        step.reward += 1.0;
        break;
      }
    }
  }
}

void Seaquest::MoveDivers() {
  for (int i = static_cast<int>(divers_.size()) - 1; i >= 0; --i) {
    Mover& diver = divers_[i];
    bool collected = AtSub(diver) && diver_count_ < kMaxDivers;
    if (!collected) {
      if (diver.move_timer == 0) {
        diver.move_timer = kDiverMoveInterval;
        Advance(diver);
        if (!OnGrid(diver.x)) {
          divers_.erase(divers_.begin() + i);
          continue;
        }
        collected = AtSub(diver) && diver_count_ < kMaxDivers;
      } else {
        --diver.move_timer;
      }
    }
    if (collected) {
      divers_.erase(divers_.begin() + i);
      ++diver_count_;
    }
  }
}

void Seaquest::MoveEnemyBullets() {
  for (int i = static_cast<int>(e_bullets_.size()) - 1; i >= 0; --i) {
    Mover& bullet = e_bullets_[i];
    if (AtSub(bullet)) terminal_ = true;
    Advance(bullet);
    if (!OnGrid(bullet.x)) {
      e_bullets_.erase(e_bullets_.begin() + i);
    } else if (AtSub(bullet)) {
      terminal_ = true;
    }
  }
}

void Seaquest::UseOxygen(GameStep& step) {
  if (oxygen_ <= 0) terminal_ = true;
  if (sub_y_ > 0) {
    --oxygen_;
    surface_ = false;
  } else if (!surface_) {
    if (diver_count_ == 0) {
      terminal_ = true;
    } else {
      step.reward += Surface();
    }
  }
}

void Seaquest::Observe(absl::Span<uint8_t> grid) const {
  std::fill(grid.begin(), grid.end(), 0);
  grid[Cell(0, sub_y_, sub_x_)] = 1;
  const int back_x = facing_right_ ? sub_x_ - 1 : sub_x_ + 1;
  if (OnGrid(back_x)) grid[Cell(1, sub_y_, back_x)] = 1;
  const int oxygen_cells = std::max(0, oxygen_) * 10 / kMaxOxygen;
  for (int x = 0; x < oxygen_cells; ++x) grid[Cell(7, 9, x)] = 1;
  for (int x = std::max(0, 9 - diver_count_); x < 9; ++x) {
    grid[Cell(8, 9, x)] = 1;
  }
  for (const Mover& bullet : f_bullets_) grid[Cell(2, bullet.y, bullet.x)] = 1;
  for (const Mover& bullet : e_bullets_) grid[Cell(4, bullet.y, bullet.x)] = 1;
  const auto draw = [&](const std::vector<Mover>& movers, int channel) {
    for (const Mover& mover : movers) {
      grid[Cell(channel, mover.y, mover.x)] = 1;
      const int trail_x = mover.moves_right ? mover.x - 1 : mover.x + 1;
      if (OnGrid(trail_x)) grid[Cell(3, mover.y, trail_x)] = 1;
    }
  };
  draw(fish_, 5);
  draw(subs_, 6);
  draw(divers_, 9);
}

}  // namespace vantage
