#ifndef VANTAGE_BENCH_TRAIN_BENCH_H_
#define VANTAGE_BENCH_TRAIN_BENCH_H_

#include <cstdint>
#include <string>

#include "bench/bare_ppo.h"

namespace vantage {

// A PPO run of `vantage train` to time end to end.
struct TrainBenchConfig {
  std::string config_path;  // the resolved run config (a --config file)
  std::string env;
  int learners = 1;
  int actors = 1;
  int envs_per_actor = 1;
  bool sync = true;
  int64_t batch = 0;   // env steps per update, all learners together
  BarePpoShape shape;  // the run's network and PPO epochs/minibatches
};

// `vantage bench train`: in one run, measures this machine's raw physics
// steps/s of the env (one core) and the bare LibTorch PPO update's
// samples/s (one core, the run's shapes), then runs the distributed main
// job (`vantage train`, a child process) and compares its steady-state env
// steps/s (the first two updates, start-up, excluded) with the machine's
// limit cores / (1/raw + epochs/bare): every env step costs its physics
// and `epochs` sample passes of the update, and nothing else is free.
// Ends with `RESULT train env=.. learners=.. actors=.. sps=.. limit_sps=..
// ratio=..`.
int RunTrainBenchmark(const TrainBenchConfig& config);

}  // namespace vantage

#endif  // VANTAGE_BENCH_TRAIN_BENCH_H_
