#ifndef VANTAGE_ACTOR_ENVS_MINATAR_MINATAR_GAME_H_
#define VANTAGE_ACTOR_ENVS_MINATAR_MINATAR_GAME_H_

// The rules of one MinAtar game (Young & Tian 2019): a 10 x 10 grid seen as
// one boolean channel per kind of object. Written from the rules of
// kenjyoung/MinAtar (minatar/environments/*.py, v1.0.15), including the
// order in which each step moves, spawns and collides things, since that
// order decides what a policy sees. docs/environments.md lists where the
// games depart from it.

#include <cstdint>
#include <random>

#include "absl/types/span.h"

namespace vantage {

constexpr int kMinAtarGridSize = 10;
constexpr int kMinAtarCells = kMinAtarGridSize * kMinAtarGridSize;

// MinAtar's full action set, in its order ('n', 'l', 'u', 'r', 'd', 'f');
// a game ignores the actions it has no use for.
enum class MinAtarAction { kNoop = 0, kLeft, kUp, kRight, kDown, kFire };
constexpr int kMinAtarActions = 6;

struct GameStep {
  double reward = 0.0;
  bool terminal = false;
};

class MinAtarGame {
 public:
  virtual ~MinAtarGame() = default;

  virtual int channels() const = 0;

  // Starts a game; every random draw of the game comes from `random`.
  virtual void Reset(std::mt19937_64& random) = 0;

  // One step; once the game is over it returns {0, true} and changes
  // nothing (as MinAtar does).
  virtual GameStep Act(MinAtarAction action, std::mt19937_64& random) = 0;

  // Writes the grid as [channels, 10, 10] zeros and ones (row 0 at the
  // top); every cell is written.
  virtual void Observe(absl::Span<uint8_t> grid) const = 0;
};

// The draws MinAtar makes with numpy (rand() < p, randint(n)), on our
// generator: the games are deterministic under a seed, not numpy's streams.
double UniformUnit(std::mt19937_64& random);
int UniformBelow(std::mt19937_64& random, int n);

// Grid index of (channel, row y, column x).
inline int Cell(int channel, int y, int x) {
  return channel * kMinAtarCells + y * kMinAtarGridSize + x;
}
inline bool OnGrid(int x) { return x >= 0 && x < kMinAtarGridSize; }

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MINATAR_MINATAR_GAME_H_
