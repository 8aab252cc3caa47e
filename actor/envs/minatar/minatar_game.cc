#include "actor/envs/minatar/minatar_game.h"

namespace vantage {

double UniformUnit(std::mt19937_64& random) {
  return std::uniform_real_distribution<double>(0.0, 1.0)(random);
}

int UniformBelow(std::mt19937_64& random, int n) {
  return std::uniform_int_distribution<int>(0, n - 1)(random);
}

}  // namespace vantage
