#ifndef VANTAGE_TESTS_FAKES_VECTOR_SPEC_H_
#define VANTAGE_TESTS_FAKES_VECTOR_SPEC_H_

// The spec of a vector task of the given sizes, for tests of the networks:
// `actions` choices when discrete, else a box of `actions` in [-1, 1].

#include <cstdint>

#include "common/env/environment.h"

namespace vantage {

inline EnvSpec VectorSpec(bool discrete, int64_t observations,
                          int64_t actions) {
  EnvSpec spec;
  spec.name = "test";
  spec.observation_size = observations;
  spec.discrete = discrete;
  spec.action_size = actions;
  if (!discrete) {
    spec.action_low.assign(actions, -1.0);
    spec.action_high.assign(actions, 1.0);
  }
  return spec;
}

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_VECTOR_SPEC_H_
