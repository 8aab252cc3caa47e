#ifndef VANTAGE_TESTS_FUZZ_FUZZ_FIXTURES_H_
#define VANTAGE_TESTS_FUZZ_FUZZ_FIXTURES_H_

// The fixed run shapes the fuzzers check their inputs against and the
// checks they share, also used by make_corpus.cc so that the seeds fit.
// Nothing here links MuJoCo.

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/env/environment.h"
#include "common/rollout/segment.h"
#include "learner/learner_core.h"

namespace vantage {

// A run's segments have at most this many steps.
inline constexpr int64_t kFuzzMaxSteps = 128;

// Observation 4, one continuous action in [-3, 3], time limit 1000.
EnvSpec FuzzContinuousSpec();
// Observation 4, three discrete actions, time limit 50.
EnvSpec FuzzDiscreteSpec();

// A learner small enough to create once per input: FuzzContinuousSpec, one
// hidden layer of 8, two rollouts of 20 steps (a multiple of A2C's 5) per
// batch, reward scaling on.
LearnerConfig FuzzLearnerConfig(const std::string& algorithm);

// FuzzLearnerConfig("ppo") with an EX2 bonus small enough to fit from the
// second update on, whose pool wraps around within a few.
LearnerConfig FuzzEx2LearnerConfig();

// A segment ValidateSegment accepts for `spec` (`steps` >= 3): an episode
// that terminates after step 0, one that a time limit truncates after step
// 2, and one still running; the values are drawn from `seed`.
Segment FuzzSegment(const EnvSpec& spec, int64_t steps, int64_t env_slot,
                    int64_t policy_version, uint64_t seed);

// ReadCheckpointExtras, then ReadCheckpoint with FuzzLearnerConfig("ppo"),
// or "a2c" or "trpo" when the checkpoint says it was trained with those.
absl::StatusOr<std::unique_ptr<LearnerCore>> ReadFuzzCheckpoint(
    const std::string& path);
// ReadCheckpointExtras, then ReadCheckpoint with FuzzEx2LearnerConfig().
absl::StatusOr<std::unique_ptr<LearnerCore>> ReadFuzzEx2Checkpoint(
    const std::string& path);

// What a learner read from a checkpoint must allow: its weights are finite
// (it publishes them) and it completes one update of valid segments.
void CheckLoadedLearner(LearnerCore& learner);

// A per-process file name under $TMPDIR (or /tmp) for fuzzers whose code
// under test reads files.
std::string FuzzTempPath(const std::string& name);

// What a fuzzer does when an invariant of the code under test breaks: a
// crash libFuzzer reports with the input, after saying which invariant.
[[noreturn]] void FuzzFail(const char* what, const absl::Status& status);

}  // namespace vantage

#endif  // VANTAGE_TESTS_FUZZ_FUZZ_FIXTURES_H_
