#include "actor/envs/minatar/breakout.h"

#include <algorithm>
#include <numeric>

namespace vantage {
namespace {

constexpr int kDx[4] = {-1, 1, 1, -1};
constexpr int kDy[4] = {-1, -1, 1, 1};
constexpr int kFlipHorizontal[4] = {1, 0, 3, 2};
constexpr int kFlipVertical[4] = {3, 2, 1, 0};
constexpr int kReverse[4] = {2, 3, 0, 1};
constexpr int kBottom = kMinAtarGridSize - 1;

void FillBrickRows(std::array<uint8_t, kMinAtarCells>& bricks) {
  for (int y = 1; y <= 3; ++y) {
    for (int x = 0; x < kMinAtarGridSize; ++x) {
      bricks[y * kMinAtarGridSize + x] = 1;
    }
  }
}

}  // namespace

int Breakout::bricks() const {
  return std::accumulate(brick_map_.begin(), brick_map_.end(), 0);
}

void Breakout::Reset(std::mt19937_64& random) {
  ball_y_ = 3;
  if (UniformBelow(random, 2) == 0) {
    ball_x_ = 0;
    ball_dir_ = 2;
  } else {
    ball_x_ = kBottom;
    ball_dir_ = 3;
  }
  paddle_ = 4;
  brick_map_.fill(0);
  FillBrickRows(brick_map_);
  strike_ = false;
  last_x_ = ball_x_;
  last_y_ = ball_y_;
  terminal_ = false;
}

GameStep Breakout::Act(MinAtarAction action, std::mt19937_64&) {
  GameStep step;
  if (terminal_) {
    step.terminal = true;
    return step;
  }
  if (action == MinAtarAction::kLeft) paddle_ = std::max(0, paddle_ - 1);
  if (action == MinAtarAction::kRight) {
    paddle_ = std::min(kBottom, paddle_ + 1);
  }

  last_x_ = ball_x_;
  last_y_ = ball_y_;
  int new_x = ball_x_ + kDx[ball_dir_];
  int new_y = ball_y_ + kDy[ball_dir_];
  bool strike_toggle = false;
  if (!OnGrid(new_x)) {
    new_x = std::clamp(new_x, 0, kBottom);
    ball_dir_ = kFlipHorizontal[ball_dir_];
  }
  if (new_y < 0) {
    new_y = 0;
    ball_dir_ = kFlipVertical[ball_dir_];
  } else if (brick_map_[new_y * kMinAtarGridSize + new_x]) {
    strike_toggle = true;
    if (!strike_) {
      step.reward += 1.0;
      strike_ = true;
      brick_map_[new_y * kMinAtarGridSize + new_x] = 0;
      new_y = last_y_;
      ball_dir_ = kFlipVertical[ball_dir_];
    }
  } else if (new_y == kBottom) {
    if (bricks() == 0) FillBrickRows(brick_map_);
    // The paddle has already moved this step. Under the ball's old column
    // it flips the ball's vertical direction only; under its new column (a
    // diagonal hit) it sends it back the way it came.
    if (ball_x_ == paddle_) {
      ball_dir_ = kFlipVertical[ball_dir_];
      new_y = last_y_;
    } else if (new_x == paddle_) {
      ball_dir_ = kReverse[ball_dir_];
      new_y = last_y_;
    } else {
      terminal_ = true;
    }
  }
  if (!strike_toggle) strike_ = false;
  ball_x_ = new_x;
  ball_y_ = new_y;
  step.terminal = terminal_;
  return step;
}

void Breakout::Observe(absl::Span<uint8_t> grid) const {
  std::fill(grid.begin(), grid.end(), 0);
  grid[Cell(0, kBottom, paddle_)] = 1;
  grid[Cell(1, ball_y_, ball_x_)] = 1;
  grid[Cell(2, last_y_, last_x_)] = 1;
  std::copy(brick_map_.begin(), brick_map_.end(), grid.begin() + Cell(3, 0, 0));
}

}  // namespace vantage
