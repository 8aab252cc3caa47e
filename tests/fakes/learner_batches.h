#ifndef VANTAGE_TESTS_FAKES_LEARNER_BATCHES_H_
#define VANTAGE_TESTS_FAKES_LEARNER_BATCHES_H_

// A small learner fed by a real actor core (Hopper, two envs), for tests of
// what an update does to the learner's state.

#include <memory>
#include <string>
#include <vector>

#include "actor/actor_core.h"
#include "common/rollout/segment.h"
#include "learner/learner_core.h"

namespace vantage {

inline constexpr int64_t kTestHorizon = 64;
inline constexpr int kTestEnvs = 2;

// PPO (4 minibatches, 2 epochs), A2C or TRPO with maxabs at rho 0.5 and
// reward scaling, kTestEnvs rollouts of kTestHorizon steps (A2C: 60).
// "ppo_gru": PPO with TestNetwork's core.
LearnerConfig TestLearnerConfig(const EnvSpec& spec,
                                const std::string& algorithm);
// The networks of TestLearnerConfig(spec, algorithm): "..._gru" has a GRU
// of 16 units trained in chunks of 16 steps.
NetworkConfig TestNetwork(const std::string& algorithm);

std::unique_ptr<ActorCore> MakeTestActor(
    int64_t segment_length = kTestHorizon, const std::string& env = "Hopper",
    const NetworkConfig& network = NetworkConfig());

// One batch of segments acted by `learner`'s current weights.
std::vector<Segment> ActOneBatch(ActorCore& actor, LearnerCore& learner);

// Runs one update on `batch` (which must complete a batch).
UpdateStats UpdateWith(LearnerCore& learner, const std::vector<Segment>& batch);

// Both learners publish the same weights and normaliser (gtest failures
// otherwise).
void ExpectSameWeights(LearnerCore& a, LearnerCore& b);

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_LEARNER_BATCHES_H_
