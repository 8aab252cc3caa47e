#ifndef VANTAGE_ACTOR_ENVS_MINATAR_SPACE_INVADERS_H_
#define VANTAGE_ACTOR_ENVS_MINATAR_SPACE_INVADERS_H_

#include <array>

#include "actor/envs/minatar/minatar_game.h"

namespace vantage {

// MinAtar SpaceInvaders: a cannon on the bottom row under a block of 4 x 6
// aliens that moves sideways and steps down at the edges, faster as it
// thins out (every min(aliens, interval) steps); the alien nearest the
// cannon fires every 10 steps; the cannon may fire every 5. +1 per alien;
// a cleared block comes back, and with ramping each new wave moves faster
// (interval 12 down to 6). The game ends when an alien bullet or an alien
// reaches the cannon, or the block must step down from the bottom row.
// Channels: cannon, alien, alien_left, alien_right (the block by its
// direction), friendly_bullet, enemy_bullet. No randomness.
class SpaceInvaders : public MinAtarGame {
 public:
  explicit SpaceInvaders(bool ramping) : ramping_(ramping) {}

  int channels() const override { return 6; }
  void Reset(std::mt19937_64& random) override;
  GameStep Act(MinAtarAction action, std::mt19937_64& random) override;
  void Observe(absl::Span<uint8_t> grid) const override;

  int cannon() const { return cannon_; }
  int aliens() const;
  int move_interval() const { return move_interval_; }

 private:
  using Grid = std::array<uint8_t, kMinAtarCells>;

  // Act's phases, in MinAtar's order, which decides what a collision hits.
  void MoveCannon(MinAtarAction action);
  void MoveBullets();
  void MoveAliens();
  void AliensFire();
  // Removes each alien a friendly bullet reached, with the bullet; returns
  // how many.
  int HitAliens();

  const bool ramping_;
  int cannon_ = 0;
  Grid friendly_bullets_{};
  Grid enemy_bullets_{};
  Grid aliens_{};
  int alien_direction_ = -1;
  int move_interval_ = 0;
  int move_timer_ = 0;
  int shot_timer_alien_ = 0;
  int shot_timer_ = 0;
  bool terminal_ = true;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MINATAR_SPACE_INVADERS_H_
