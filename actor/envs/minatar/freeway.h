#ifndef VANTAGE_ACTOR_ENVS_MINATAR_FREEWAY_H_
#define VANTAGE_ACTOR_ENVS_MINATAR_FREEWAY_H_

#include <array>

#include "actor/envs/minatar/minatar_game.h"

namespace vantage {

// MinAtar Freeway: a chicken in column 4 crosses eight lanes of cars (rows
// 1-8), moving at most one row every 3 steps; each car has a random speed
// (a move every 2 to 6 steps) and direction, wrapping round the road. A
// car sends the chicken back to the bottom row; reaching the top scores +1,
// puts it back at the bottom and redraws the speeds. The game ends after
// 2500 steps (on the 2501st, as MinAtar counts). Channels: chicken, car,
// and speed1..speed5 marking each car's trail by its speed.
class Freeway : public MinAtarGame {
 public:
  int channels() const override { return 7; }
  void Reset(std::mt19937_64& random) override;
  GameStep Act(MinAtarAction action, std::mt19937_64& random) override;
  void Observe(absl::Span<uint8_t> grid) const override;

  int chicken() const { return chicken_; }

  struct Car {
    int x = 0;
    int y = 0;
    int timer = 0;
    int speed = 0;  // +-1..5, positive to the right
  };
  const std::array<Car, 8>& cars() const { return cars_; }

 private:
  void RandomizeCars(bool initialize, std::mt19937_64& random);

  int chicken_ = 0;
  int move_timer_ = 0;
  int terminate_timer_ = 0;
  bool terminal_ = true;
  std::array<Car, 8> cars_{};
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MINATAR_FREEWAY_H_
