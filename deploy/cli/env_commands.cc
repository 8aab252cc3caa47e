#include "deploy/cli/env_commands.h"

#include <ATen/CPUGeneratorImpl.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <random>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "actor/envs/env_registry.h"
#include "deploy/trained_policy.h"

namespace vantage {
namespace {

constexpr int kBadInputExitCode = 2;

int Fail(const char* command, const absl::Status& status) {
  std::fprintf(stderr, "vantage %s: %s\n", command,
               absl::StrReplaceAll(status.message(), {{"\n", " "}}).c_str());
  return kBadInputExitCode;
}

// FNV-1a over the observations' bytes: cheap, and any change shows.
class Digest {
 public:
  void Add(const std::vector<double>& values) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
    for (size_t i = 0; i < values.size() * sizeof(double); ++i) {
      hash_ = (hash_ ^ bytes[i]) * 0x100000001b3ULL;
    }
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 0xcbf29ce484222325ULL;
};

}  // namespace

int RunEnvsCommand() {
  for (const std::string& name : RegisteredEnvironments()) {
    absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
    if (!env.ok()) return Fail("envs", env.status());
    const EnvSpec& spec = (*env)->spec();
    std::printf("%s obs=[%ld] act=%s\n", name.c_str(),
                static_cast<long>(spec.observation_size),
                spec.ActionString().c_str());
  }
  return 0;
}

int RunRolloutCommand(const RolloutRequest& request) {
  const int64_t episodes = request.episodes;
  const uint64_t seed = request.seed;
  std::string env_name = request.env;
  std::optional<TrainedPolicy> trained;
  if (!request.checkpoint.empty()) {
    absl::StatusOr<TrainedPolicy> loaded =
        LoadTrainedPolicy(request.checkpoint);
    if (!loaded.ok()) return Fail("rollout", loaded.status());
    trained = *std::move(loaded);
    if (env_name.empty()) env_name = trained->config.env();
    if (env_name != trained->config.env()) {
      return Fail("rollout", absl::InvalidArgumentError(absl::StrCat(
                                 "the checkpoint's policy was trained on ",
                                 trained->config.env(), ", not ", env_name)));
    }
    std::printf("policy: %s (version %ld, %s actions)\n",
                trained->checkpoint_path.c_str(),
                static_cast<long>(trained->version),
                request.stochastic ? "sampled" : "deterministic");
  }
  at::Generator generator = at::detail::createCPUGenerator(seed);
  if (env_name.empty()) {
    return Fail("rollout", absl::InvalidArgumentError(
                               "--env=NAME is required (see `vantage envs`)"));
  }
  if (episodes < 1) {
    return Fail("rollout",
                absl::InvalidArgumentError("--episodes must be >= 1"));
  }
  absl::StatusOr<std::unique_ptr<Environment>> made = MakeEnvironment(env_name);
  if (!made.ok()) return Fail("rollout", made.status());
  Environment& env = **made;
  const EnvSpec& spec = env.spec();
  std::mt19937_64 rng(seed);
  std::vector<double> observation(spec.observation_size);
  std::vector<double> action(spec.discrete ? 1 : spec.action_size);
  Digest digest;
  double total_return = 0.0;
  int64_t total_length = 0;
  for (int64_t episode = 0; episode < episodes; ++episode) {
    if (absl::Status status =
            env.Reset(seed * 1000003 + episode, absl::MakeSpan(observation));
        !status.ok()) {
      return Fail("rollout", status);
    }
    digest.Add(observation);
    double episode_return = 0.0;
    int64_t length = 0;
    while (true) {
      if (trained.has_value()) {
        action = trained->Act(observation, !request.stochastic, generator);
      } else if (spec.discrete) {
        action[0] = static_cast<double>(std::uniform_int_distribution<int64_t>(
            0, spec.action_size - 1)(rng));
      } else {
        for (size_t i = 0; i < action.size(); ++i) {
          // Unbounded actuators get actions in [-1, 1].
          const double low =
              std::isfinite(spec.action_low[i]) ? spec.action_low[i] : -1.0;
          const double high =
              std::isfinite(spec.action_high[i]) ? spec.action_high[i] : 1.0;
          action[i] = std::uniform_real_distribution<double>(low, high)(rng);
        }
      }
      absl::StatusOr<StepResult> result =
          env.Step(action, absl::MakeSpan(observation));
      if (!result.ok()) return Fail("rollout", result.status());
      digest.Add(observation);
      episode_return += result->reward;
      ++length;
      if (result->terminated || result->truncated) {
        std::printf("episode %ld return=%.3f length=%ld %s\n",
                    static_cast<long>(episode), episode_return,
                    static_cast<long>(length),
                    result->terminated ? "terminated" : "truncated");
        break;
      }
    }
    total_return += episode_return;
    total_length += length;
  }
  std::printf(
      "RESULT rollout env=%s obs_dim=%ld act_dim=%ld episodes=%ld "
      "mean_return=%.3f mean_length=%.1f digest=%016lx\n",
      env_name.c_str(), static_cast<long>(spec.observation_size),
      static_cast<long>(spec.action_size), static_cast<long>(episodes),
      total_return / episodes, static_cast<double>(total_length) / episodes,
      static_cast<unsigned long>(digest.value()));
  return 0;
}

}  // namespace vantage
