#ifndef VANTAGE_BENCH_RAW_PHYSICS_H_
#define VANTAGE_BENCH_RAW_PHYSICS_H_

// The baseline of the environment and actor benchmarks: the bare physics
// engine under an environment (for the MinAtar games: the bare rules), with
// nothing of the task around it.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

// A fixed, in-bounds action for every actuator: the same work each step.
inline constexpr double kBenchAction = 0.2;

// The action benchmarks repeat: kBenchAction on every actuator, or the
// first action (a game's noop) of a discrete environment.
std::vector<double> BenchAction(const EnvSpec& spec);

class RawPhysics {
 public:
  virtual ~RawPhysics() = default;
  virtual int frame_skip() const = 0;
  // Back to the model's initial state.
  virtual void Restart() = 0;
  // One environment step's worth of physics.
  virtual void Step() = 0;
};

// The bare physics of `env`'s model (inside its time limit): MuJoCo's
// mj_step or the env's Bullet world, kBenchAction on every actuator, frame
// skip included; for a MinAtar game its rules and grid, playing noop.
// nullptr if the environment has no engine this knows.
std::unique_ptr<RawPhysics> MakeRawPhysics(const Environment& env);

// How many steps `env`'s episodes last under kBenchAction (a baseline
// restarts its physics as often, so both sides simulate the same kind of
// states: a fallen body in permanent contact steps at another speed).
absl::StatusOr<int64_t> FixedActionEpisodeLength(Environment& env);

// Registers Google benchmark `name`: one bare physics step per iteration,
// restarted every `episode_length` steps. `physics` must outlive the run.
void RegisterRawBenchmark(const std::string& name, RawPhysics& physics,
                          int64_t episode_length);

}  // namespace vantage

#endif  // VANTAGE_BENCH_RAW_PHYSICS_H_
