#ifndef VANTAGE_BENCH_ENV_BENCH_H_
#define VANTAGE_BENCH_ENV_BENCH_H_

#include <string>

namespace vantage {

// `vantage bench env --env=NAME`: on one core, env steps per second of
// the bare physics of the same model (mj_step or Bullet's stepSimulation,
// frame skip included, fixed actions, restarted as often as the
// environment's episodes end under that action),
// of the environment through the interface (time limit and resets included)
// and of a 16-env VectorEnv; ends with `RESULT env name=NAME
// raw_steps_per_s=<x> env_steps_per_s=<y> vec16_steps_per_s=<z>
// ratio=<vec16/raw>`. Returns the exit code.
int RunEnvBenchmark(const std::string& env_name);

}  // namespace vantage

#endif  // VANTAGE_BENCH_ENV_BENCH_H_
