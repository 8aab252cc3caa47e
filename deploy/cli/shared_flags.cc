#include "deploy/cli/shared_flags.h"

#include "absl/flags/flag.h"

ABSL_FLAG(std::string, env, "",
          "environment name (see `vantage envs`), mjcf:PATH, "
          "python:MODULE:CALLABLE or gym:ID");
ABSL_FLAG(std::string, env_kwargs, "",
          "a Python environment's factory keyword arguments, a JSON object "
          "(python:... and gym:... environments only)");
ABSL_FLAG(int, envs, 1, "environments stepped together");
ABSL_FLAG(uint64_t, seed, 0, "random seed");
ABSL_FLAG(std::string, learner, "", "the learner's HOST:PORT");
ABSL_FLAG(std::string, metrics, "",
          "serve Prometheus metrics on PORT (127.0.0.1) or HOST:PORT (port "
          "0: a free one, printed on stderr); with train, the learner there "
          "and the actors on the next ports, listed in "
          "RUN_DIR/prometheus_targets.json (docs/metrics.md); empty: none");
ABSL_FLAG(std::string, checkpoint, "",
          "a run directory (its newest checkpoint that loads) or checkpoint "
          "file whose policy acts (rollout's default: a uniform-random "
          "policy)");
ABSL_FLAG(std::string, out, "",
          "experiment run: the experiment directory (created; an existing "
          "one is continued); export: the ONNX file to write");
ABSL_FLAG(std::string, metrics_port_file, "",
          "with --metrics, write the metrics port to this file once serving");
