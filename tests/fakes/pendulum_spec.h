#ifndef VANTAGE_TESTS_FAKES_PENDULUM_SPEC_H_
#define VANTAGE_TESTS_FAKES_PENDULUM_SPEC_H_

// The registered InvertedPendulum's spec, written out, as an honest actor
// registers it: for tests of the learner service that need no MuJoCo.

#include <cstdint>

#include "common/env/environment.h"
#include "proto/vantage.pb.h"

namespace vantage {

inline constexpr int64_t kPendulumObservationSize = 4;
inline constexpr int64_t kPendulumActionSize = 1;

EnvSpec PendulumSpec();
pb::EnvSpec PendulumSpecProto();

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_PENDULUM_SPEC_H_
