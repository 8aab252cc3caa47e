#include "tests/fakes/pendulum_spec.h"

#include "proto/wire_format.h"

namespace vantage {

EnvSpec PendulumSpec() {
  EnvSpec spec;
  spec.name = "InvertedPendulum";
  spec.observation_size = kPendulumObservationSize;
  spec.discrete = false;
  spec.action_size = kPendulumActionSize;
  spec.action_low = {-3.0};
  spec.action_high = {3.0};
  spec.max_episode_steps = 1000;
  spec.control_dt = 0.04;
  return spec;
}

pb::EnvSpec PendulumSpecProto() {
  pb::EnvSpec proto;
  EnvSpecToProto(PendulumSpec(), &proto);
  return proto;
}

}  // namespace vantage
