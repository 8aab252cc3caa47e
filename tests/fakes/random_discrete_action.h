#ifndef VANTAGE_TESTS_FAKES_RANDOM_DISCRETE_ACTION_H_
#define VANTAGE_TESTS_FAKES_RANDOM_DISCRETE_ACTION_H_

// Random discrete actions that an environment with action masks takes: a
// uniform choice per head among the legal ones.

#include <cstdint>
#include <random>
#include <vector>

#include "common/env/environment.h"

namespace vantage {

// One index per head of `spec` (discrete), uniform among the choices
// `mask` allows (action_size bytes, each head's in turn; null: all).
inline std::vector<double> RandomDiscreteAction(const EnvSpec& spec,
                                                const uint8_t* mask,
                                                std::mt19937_64& rng) {
  std::vector<double> action;
  int64_t offset = 0;
  for (int64_t choices : spec.action_heads()) {
    std::vector<int64_t> legal;
    for (int64_t i = 0; i < choices; ++i) {
      if (mask == nullptr || mask[offset + i]) legal.push_back(i);
    }
    action.push_back(
        static_cast<double>(legal[std::uniform_int_distribution<size_t>(
            0, legal.size() - 1)(rng)]));
    offset += choices;
  }
  return action;
}

// The same for `env` in its current state (its mask, if it has masks).
inline std::vector<double> RandomDiscreteAction(const Environment& env,
                                                std::mt19937_64& rng) {
  const absl::StatusOr<std::vector<uint8_t>> mask = ReadActionMask(env);
  const bool masked = mask.ok() && !mask->empty();
  return RandomDiscreteAction(env.spec(), masked ? mask->data() : nullptr, rng);
}

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_RANDOM_DISCRETE_ACTION_H_
