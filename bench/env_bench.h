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
// ratio=<vec16/raw>`. A Python environment (python:... or gym:..., with
// `env_kwargs`) is held against the same environment stepped by a plain
// Python loop under the same action instead: `RESULT env name=NAME
// python_steps_per_s=<p> env_steps_per_s=<y> vec16_steps_per_s=<z>
// ratio=<y/p>`. Returns the exit code.
int RunEnvBenchmark(const std::string& env_name,
                    const std::string& env_kwargs = "");

}  // namespace vantage

#endif  // VANTAGE_BENCH_ENV_BENCH_H_
