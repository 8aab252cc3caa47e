#ifndef VANTAGE_ACTOR_ENVS_MINATAR_SEAQUEST_H_
#define VANTAGE_ACTOR_ENVS_MINATAR_SEAQUEST_H_

#include <vector>

#include "actor/envs/minatar/minatar_game.h"

namespace vantage {

// MinAtar Seaquest: a submarine (rows 0-8, row 0 the surface) shoots enemy
// fish and subs (+1 each) that cross the rows from either side, enemy subs
// firing as they go, and picks up divers (at most 6). Below the surface
// oxygen drains from 200, one per step, and the game ends when it runs
// out; surfacing costs a diver and refills it, with all six it also scores
// oxygen / 20 (0-10), and surfacing without a diver ends the game, as does
// touching an enemy or its bullet. Each surfacing with divers ramps up the
// difficulty (enemies spawn from every 20 steps down to every step and
// move from every 6 down to every 3 steps). Channels: sub_front,
// sub_back, friendly_bullet, trail, enemy_bullet, enemy_fish, enemy_sub,
// oxygen_gauge, diver_gauge, diver.
class Seaquest : public MinAtarGame {
 public:
  explicit Seaquest(bool ramping) : ramping_(ramping) {}

  int channels() const override { return 10; }
  void Reset(std::mt19937_64& random) override;
  GameStep Act(MinAtarAction action, std::mt19937_64& random) override;
  void Observe(absl::Span<uint8_t> grid) const override;

  int sub_x() const { return sub_x_; }
  int sub_y() const { return sub_y_; }
  int oxygen() const { return oxygen_; }
  int divers_on_board() const { return diver_count_; }
  int enemy_spawn_interval() const { return enemy_spawn_speed_; }

  // x, row, direction and timers of everything that moves.
  struct Mover {
    int x = 0;
    int y = 0;
    bool moves_right = false;
    int move_timer = 0;
    int shot_timer = 0;  // enemy subs only
  };
  const std::vector<Mover>& fish() const { return fish_; }
  const std::vector<Mover>& enemy_subs() const { return subs_; }
  const std::vector<Mover>& divers() const { return divers_; }
  const std::vector<Mover>& friendly_bullets() const { return f_bullets_; }
  const std::vector<Mover>& enemy_bullets() const { return e_bullets_; }

 private:
  // A step's parts, in the order Act runs them.
  void MoveSub(MinAtarAction action);
  void MoveFriendlyBullets(GameStep& step);
  void MoveDivers();
  void MoveEnemyBullets();
  // Oxygen runs down under water; surfacing with divers scores, without
  // any ends the game.
  void UseOxygen(GameStep& step);
  void SpawnEnemy(std::mt19937_64& random);
  void SpawnDiver(std::mt19937_64& random);
  // Moves the enemies (fish or subs) newest first; subs also fire.
  void MoveEnemies(std::vector<Mover>& enemies, bool fire, GameStep& step);
  double Surface();
  bool AtSub(const Mover& mover) const {
    return mover.x == sub_x_ && mover.y == sub_y_;
  }

  const bool ramping_;
  int sub_x_ = 0;
  int sub_y_ = 0;
  bool facing_right_ = false;
  int oxygen_ = 0;
  int diver_count_ = 0;
  int enemy_spawn_speed_ = 0;
  int enemy_spawn_timer_ = 0;
  int diver_spawn_timer_ = 0;
  int move_speed_ = 0;
  int ramp_index_ = 0;
  int shot_timer_ = 0;
  bool surface_ = true;
  bool terminal_ = true;
  std::vector<Mover> f_bullets_;
  std::vector<Mover> e_bullets_;
  std::vector<Mover> fish_;
  std::vector<Mover> subs_;
  std::vector<Mover> divers_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MINATAR_SEAQUEST_H_
