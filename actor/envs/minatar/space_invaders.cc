#include "actor/envs/minatar/space_invaders.h"

#include <algorithm>
#include <cstdlib>
#include <numeric>

namespace vantage {
namespace {

constexpr int kShotCoolDown = 5;
constexpr int kMoveInterval = 12;
constexpr int kFastestMoveInterval = 6;
constexpr int kAlienShotInterval = 10;
constexpr int kN = kMinAtarGridSize;
constexpr int kBottom = kN - 1;

using Grid = std::array<uint8_t, kMinAtarCells>;

uint8_t& At(Grid& grid, int y, int x) { return grid[y * kN + x]; }
uint8_t At(const Grid& grid, int y, int x) { return grid[y * kN + x]; }

void FillWave(Grid& aliens) {
  for (int y = 0; y < 4; ++y) {
    for (int x = 2; x < 8; ++x) At(aliens, y, x) = 1;
  }
}

bool ColumnHas(const Grid& grid, int x) {
  for (int y = 0; y < kN; ++y) {
    if (At(grid, y, x)) return true;
  }
  return false;
}

bool RowHas(const Grid& grid, int y) {
  for (int x = 0; x < kN; ++x) {
    if (At(grid, y, x)) return true;
  }
  return false;
}

// numpy.roll: everything moves `dy` rows and `dx` columns, wrapping round.
Grid Rolled(const Grid& grid, int dy, int dx) {
  Grid out{};
  for (int y = 0; y < kN; ++y) {
    for (int x = 0; x < kN; ++x) {
      At(out, (y + dy + kN) % kN, (x + dx + kN) % kN) = At(grid, y, x);
    }
  }
  return out;
}

}  // namespace

int SpaceInvaders::aliens() const {
  return std::accumulate(aliens_.begin(), aliens_.end(), 0);
}

void SpaceInvaders::Reset(std::mt19937_64&) {
  cannon_ = 5;
  friendly_bullets_.fill(0);
  enemy_bullets_.fill(0);
  aliens_.fill(0);
  FillWave(aliens_);
  alien_direction_ = -1;
  move_interval_ = kMoveInterval;
  move_timer_ = move_interval_;
  shot_timer_alien_ = kAlienShotInterval;
  shot_timer_ = 0;
  terminal_ = false;
}

GameStep SpaceInvaders::Act(MinAtarAction action, std::mt19937_64&) {
  GameStep step;
  if (terminal_) {
    step.terminal = true;
    return step;
  }
  MoveCannon(action);
  MoveBullets();
  if (At(aliens_, kBottom, cannon_)) terminal_ = true;
  if (move_timer_ == 0) MoveAliens();
  if (shot_timer_alien_ == 0) AliensFire();
  step.reward += HitAliens();

  if (shot_timer_ > 0) --shot_timer_;
  --move_timer_;
  --shot_timer_alien_;

  if (aliens() == 0) {
    if (ramping_ && move_interval_ > kFastestMoveInterval) --move_interval_;
    FillWave(aliens_);
  }
  step.terminal = terminal_;
  return step;
}

void SpaceInvaders::MoveCannon(MinAtarAction action) {
  if (action == MinAtarAction::kFire && shot_timer_ == 0) {
    At(friendly_bullets_, kBottom, cannon_) = 1;
    shot_timer_ = kShotCoolDown;
  } else if (action == MinAtarAction::kLeft) {
    cannon_ = std::max(0, cannon_ - 1);
  } else if (action == MinAtarAction::kRight) {
    cannon_ = std::min(kBottom, cannon_ + 1);
  }
}

void SpaceInvaders::MoveBullets() {
  // As MinAtar moves them (numpy.roll): a bullet leaving the grid wraps
  // round and is cleared at once, so it simply disappears.
  friendly_bullets_ = Rolled(friendly_bullets_, -1, 0);
  for (int x = 0; x < kN; ++x) At(friendly_bullets_, kBottom, x) = 0;
  enemy_bullets_ = Rolled(enemy_bullets_, 1, 0);
  for (int x = 0; x < kN; ++x) At(enemy_bullets_, 0, x) = 0;
  if (At(enemy_bullets_, kBottom, cannon_)) terminal_ = true;
}

void SpaceInvaders::MoveAliens() {
  move_timer_ = std::min(aliens(), move_interval_);
  if ((alien_direction_ < 0 && ColumnHas(aliens_, 0)) ||
      (alien_direction_ > 0 && ColumnHas(aliens_, kBottom))) {
    alien_direction_ = -alien_direction_;
    if (RowHas(aliens_, kBottom)) terminal_ = true;
    aliens_ = Rolled(aliens_, 1, 0);
  } else {
    aliens_ = Rolled(aliens_, 0, alien_direction_);
  }
  if (At(aliens_, kBottom, cannon_)) terminal_ = true;
}

void SpaceInvaders::AliensFire() {
  shot_timer_alien_ = kAlienShotInterval;
  // The lowest alien of the column nearest the cannon (ties: the column
  // to the left).
  int column = -1;
  for (int distance = 0; distance < kN && column < 0; ++distance) {
    for (int x : {cannon_ - distance, cannon_ + distance}) {
      if (OnGrid(x) && ColumnHas(aliens_, x)) {
        column = x;
        break;
      }
    }
  }
  if (column >= 0) {
    int row = kBottom;
    while (!At(aliens_, row, column)) --row;
    At(enemy_bullets_, row, column) = 1;
  }
}

int SpaceInvaders::HitAliens() {
  int hits = 0;
  for (int i = 0; i < kMinAtarCells; ++i) {
    if (aliens_[i] && friendly_bullets_[i]) {
      aliens_[i] = 0;
      friendly_bullets_[i] = 0;
      ++hits;
    }
  }
  return hits;
}

void SpaceInvaders::Observe(absl::Span<uint8_t> grid) const {
  std::fill(grid.begin(), grid.end(), 0);
  grid[Cell(0, kBottom, cannon_)] = 1;
  const int direction_channel = alien_direction_ < 0 ? 2 : 3;
  for (int i = 0; i < kMinAtarCells; ++i) {
    grid[Cell(1, 0, 0) + i] = aliens_[i];
    grid[Cell(direction_channel, 0, 0) + i] = aliens_[i];
    grid[Cell(4, 0, 0) + i] = friendly_bullets_[i];
    grid[Cell(5, 0, 0) + i] = enemy_bullets_[i];
  }
}

}  // namespace vantage
