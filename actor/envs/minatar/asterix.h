#ifndef VANTAGE_ACTOR_ENVS_MINATAR_ASTERIX_H_
#define VANTAGE_ACTOR_ENVS_MINATAR_ASTERIX_H_

#include <array>

#include "actor/envs/minatar/minatar_game.h"

namespace vantage {

// MinAtar Asterix: the player moves freely over rows 1-8; enemies and gold
// (one in three) enter from either side on a free lane and cross it, all
// on one movement timer. Gold scores +1; touching an enemy ends the game.
// With ramping, every 102 steps spawns come faster (every 10 steps down to
// every step) and, every other time, movement too (every 5 down to 1).
// Channels: player, enemy, trail, gold.
class Asterix : public MinAtarGame {
 public:
  explicit Asterix(bool ramping) : ramping_(ramping) {}

  int channels() const override { return 4; }
  void Reset(std::mt19937_64& random) override;
  GameStep Act(MinAtarAction action, std::mt19937_64& random) override;
  void Observe(absl::Span<uint8_t> grid) const override;

  int player_x() const { return player_x_; }
  int player_y() const { return player_y_; }
  int spawn_interval() const { return spawn_speed_; }
  int move_interval() const { return move_speed_; }

  // Lane i (row i + 1) holds at most one entity.
  struct Entity {
    bool present = false;
    int x = 0;
    bool moves_right = false;
    bool gold = false;
  };
  const std::array<Entity, 8>& lanes() const { return lanes_; }

 private:
  void Spawn(std::mt19937_64& random);
  // Gold at the player's cell is collected, an enemy ends the game.
  void Touch(Entity& entity, GameStep& step);

  const bool ramping_;
  int player_x_ = 0;
  int player_y_ = 0;
  std::array<Entity, 8> lanes_{};
  int spawn_speed_ = 0;
  int spawn_timer_ = 0;
  int move_speed_ = 0;
  int move_timer_ = 0;
  int ramp_timer_ = 0;
  int ramp_index_ = 0;
  bool terminal_ = true;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MINATAR_ASTERIX_H_
