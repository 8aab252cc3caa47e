#include "actor/envs/minatar/freeway.h"

#include <algorithm>
#include <cstdlib>

namespace vantage {
namespace {

constexpr int kPlayerSpeed = 3;
constexpr int kTimeLimit = 2500;
constexpr int kChickenColumn = 4;
constexpr int kBottom = kMinAtarGridSize - 1;

}  // namespace

void Freeway::RandomizeCars(bool initialize, std::mt19937_64& random) {
  // All eight speeds first, then all eight directions, as MinAtar draws.
  std::array<int, 8> speeds;
  for (int& speed : speeds) speed = 1 + UniformBelow(random, 5);
  for (int& speed : speeds) {
    if (UniformBelow(random, 2) == 0) speed = -speed;
  }
  for (int i = 0; i < 8; ++i) {
    Car& car = cars_[i];
    if (initialize) {
      car.x = 0;
      car.y = i + 1;
    }
    car.timer = std::abs(speeds[i]);
    car.speed = speeds[i];
  }
}

void Freeway::Reset(std::mt19937_64& random) {
  RandomizeCars(/*initialize=*/true, random);
  chicken_ = kBottom;
  move_timer_ = kPlayerSpeed;
  terminate_timer_ = kTimeLimit;
  terminal_ = false;
}

GameStep Freeway::Act(MinAtarAction action, std::mt19937_64& random) {
  GameStep step;
  if (terminal_) {
    step.terminal = true;
    return step;
  }
  if (action == MinAtarAction::kUp && move_timer_ == 0) {
    move_timer_ = kPlayerSpeed;
    chicken_ = std::max(0, chicken_ - 1);
  } else if (action == MinAtarAction::kDown && move_timer_ == 0) {
    move_timer_ = kPlayerSpeed;
    chicken_ = std::min(kBottom, chicken_ + 1);
  }
  if (chicken_ == 0) {
    step.reward += 1.0;
    RandomizeCars(/*initialize=*/false, random);
    chicken_ = kBottom;
  }
  for (Car& car : cars_) {
    if (car.x == kChickenColumn && car.y == chicken_) chicken_ = kBottom;
    if (car.timer == 0) {
      car.timer = std::abs(car.speed);
      car.x += car.speed > 0 ? 1 : -1;
      if (car.x < 0) car.x = kBottom;
      if (car.x > kBottom) car.x = 0;
      if (car.x == kChickenColumn && car.y == chicken_) chicken_ = kBottom;
    } else {
      --car.timer;
    }
  }
  if (move_timer_ > 0) --move_timer_;
  if (--terminate_timer_ < 0) terminal_ = true;
  step.terminal = terminal_;
  return step;
}

void Freeway::Observe(absl::Span<uint8_t> grid) const {
  std::fill(grid.begin(), grid.end(), 0);
  grid[Cell(0, chicken_, kChickenColumn)] = 1;
  for (const Car& car : cars_) {
    grid[Cell(1, car.y, car.x)] = 1;
    int back_x = car.speed > 0 ? car.x - 1 : car.x + 1;
    if (back_x < 0) back_x = kBottom;
    if (back_x > kBottom) back_x = 0;
    grid[Cell(1 + std::abs(car.speed), car.y, back_x)] = 1;
  }
}

}  // namespace vantage
