#ifndef VANTAGE_BENCH_TRAIN_BENCH_H_
#define VANTAGE_BENCH_TRAIN_BENCH_H_

#include <cstdint>
#include <string>
#include <vector>

#include "bench/bare_ppo.h"
#include "common/env/environment.h"
#include "common/nn/network_config.h"
#include "learner/algorithms/a2c/a2c_config.h"

namespace vantage {

// One configuration of the run to time: its resolved run config (a
// --config file) and how it acts.
struct TrainBenchRun {
  std::string config_path;
  bool sync = true;
  int64_t max_policy_lag = 0;
};

// PPO or A2C runs of `vantage train` to time end to end, one per
// configuration, all of the same env, shapes and batch.
struct TrainBenchConfig {
  std::vector<TrainBenchRun> runs;
  std::string env;
  int learners = 1;
  int actors = 1;
  int envs_per_actor = 1;
  int64_t batch = 0;   // env steps per update, all learners together
  BarePpoShape shape;  // PPO: the run's network and epochs/minibatches
  bool a2c = false;    // else PPO
  EnvSpec spec;
  NetworkConfig network;
  A2cConfig a2c_config;
  int64_t streams = 0;  // the run's envs, all actors together
};

// `vantage bench train`: in one run, measures this machine's raw physics
// steps/s of the env (one core; a MinAtar game's bare rules) and the
// samples/s of vantage's own update of the run (PpoUpdater or A2cUpdater,
// one core, the run's networks and shapes, a synthetic batch), then runs
// the distributed main job (`vantage train`, a child process) in each
// configuration and compares its steady-state env steps/s (the first two
// updates, start-up, excluded) with the machine's limit
// cores / (1/raw + passes/update): every env step costs its physics and
// `passes` sample passes of the update (PPO's epochs, A2C's one), and
// nothing else is free. For PPO the limit with the bare LibTorch loop's
// samples/s (bare_ppo.h) in place of vantage's is printed beside it. Each
// configuration ends with `RESULT train env=.. sync=.. max_policy_lag=..
// sps=.. limit_sps=.. ratio=..` and the time splits the run's learners
// and actors printed when they stopped (mean shares in percent:
// learner_advantages=.., actor_physics=.., ...).
int RunTrainBenchmark(const TrainBenchConfig& config);

}  // namespace vantage

#endif  // VANTAGE_BENCH_TRAIN_BENCH_H_
