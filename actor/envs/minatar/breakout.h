#ifndef VANTAGE_ACTOR_ENVS_MINATAR_BREAKOUT_H_
#define VANTAGE_ACTOR_ENVS_MINATAR_BREAKOUT_H_

#include <array>

#include "actor/envs/minatar/minatar_game.h"

namespace vantage {

// MinAtar Breakout: a paddle on the bottom row, a ball moving diagonally
// one cell per step, three rows of bricks (rows 1-3) that come back once
// all are broken and the ball next reaches the bottom. +1 per brick; the
// game ends when the ball passes the paddle. Channels: paddle, ball, trail
// (the ball's previous cell), brick.
class Breakout : public MinAtarGame {
 public:
  int channels() const override { return 4; }
  void Reset(std::mt19937_64& random) override;
  GameStep Act(MinAtarAction action, std::mt19937_64& random) override;
  void Observe(absl::Span<uint8_t> grid) const override;

  int ball_x() const { return ball_x_; }
  int ball_y() const { return ball_y_; }
  // 0 up-left, 1 up-right, 2 down-right, 3 down-left.
  int ball_direction() const { return ball_dir_; }
  int paddle() const { return paddle_; }
  int bricks() const;

 private:
  int ball_x_ = 0;
  int ball_y_ = 0;
  int ball_dir_ = 0;
  int paddle_ = 0;
  int last_x_ = 0;
  int last_y_ = 0;
  // A brick was hit on the previous step: the ball then passes through
  // the next brick it meets without breaking it (MinAtar's rule).
  bool strike_ = false;
  bool terminal_ = true;
  std::array<uint8_t, kMinAtarCells> brick_map_{};
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MINATAR_BREAKOUT_H_
