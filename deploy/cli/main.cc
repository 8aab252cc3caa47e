// The `vantage` command-line tool: one binary, one subcommand per task.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"
#include "bench/advantage_bench.h"
#include "bench/env_bench.h"
#include "bench/learner_bench.h"
#include "bench/transport_bench.h"
#include "deploy/cli/actor_command.h"
#include "deploy/cli/advantages_command.h"
#include "deploy/cli/env_commands.h"
#include "deploy/cli/train_command.h"
#include "deploy/learner_server.h"
#include "learner/service/actor_gateway.h"
#include "learner/service/security.h"

ABSL_FLAG(std::string, input, "",
          "advantages: JSON file with one rollout and the estimator settings");
ABSL_FLAG(bool, example, false,
          "advantages: print every estimator on a built-in rollout");
ABSL_FLAG(std::string, env, "",
          "rollout, bench env, train: environment name (see `vantage envs`) "
          "or mjcf:PATH; train defaults to InvertedPendulum");
ABSL_FLAG(std::string, mode, "distributed",
          "train: distributed (a learner and --actors actor processes over "
          "gRPC on this machine) | local (one process)");
ABSL_FLAG(int, actors, 2, "train --mode=distributed: actor processes");
ABSL_FLAG(int, envs_per_actor, 1,
          "train --mode=distributed: environments per actor");
ABSL_FLAG(std::string, algo, "ppo", "train: ppo | a2c | trpo");
ABSL_FLAG(std::string, estimator, "maxabs",
          "train: gae | max | min | maxabs | order:D");
ABSL_FLAG(double, rho, 0.4, "train: probability of the biased estimate");
ABSL_FLAG(std::vector<std::string>, ensemble,
          std::vector<std::string>({"1", "16", "64", "2048"}),
          "train: the path ensemble's k-step lengths");
ABSL_FLAG(int64_t, steps, 150000, "train: environment steps of the run");
ABSL_FLAG(int, envs, 1, "train: environments (one rollout each per update)");
ABSL_FLAG(int64_t, horizon, 2048,
          "train: rollout length per environment (default: ppo 2048, trpo "
          "1024, a2c 5 x --minibatches)");
ABSL_FLAG(int, minibatches, 32,
          "train: ppo minibatches per epoch (32); a2c: n of the paper's 5n "
          "trick, 5n-step rollouts updated as n 5-step minibatches (4)");
ABSL_FLAG(int, epochs, 10, "train: ppo epochs per update");
ABSL_FLAG(double, learning_rate, 3e-4,
          "train: ppo 3e-4 (Adam), a2c 7e-4 (RMSProp), both decayed "
          "linearly; trpo: the value function's Adam, 1e-3");
ABSL_FLAG(double, gamma, 0.99, "train: discount");
ABSL_FLAG(double, gae_lambda, 0.95,
          "train: GAE lambda (default: ppo 0.95, trpo 0.98, a2c 1)");
ABSL_FLAG(double, entropy_coef, 0.0,
          "train: entropy bonus (default: a2c 0.01, else 0)");
ABSL_FLAG(std::vector<std::string>, hidden,
          std::vector<std::string>({"64", "64"}),
          "train: hidden layer sizes of the policy and value networks");
ABSL_FLAG(bool, scale_rewards, false,
          "train: divide rewards by the running std of discounted returns");
ABSL_FLAG(double, max_kl, 0.01, "train: trpo's trust region");
ABSL_FLAG(int, checkpoint_every, 10,
          "train: updates between checkpoints (with --run_dir)");
ABSL_FLAG(int, keep_checkpoints, 3, "train: newest checkpoints kept");
ABSL_FLAG(std::string, config, "",
          "train: JSON run config (as a run directory's config.json); flags "
          "given on the command line override it");
ABSL_FLAG(std::string, run_dir, "",
          "train: directory for config.json, progress.csv, checkpoints/");
ABSL_FLAG(std::string, resume, "",
          "train: continue the run in this directory from its last "
          "checkpoint");
ABSL_FLAG(bool, sync, true,
          "train, learner: each batch only from the current policy version "
          "(actors wait for it); --nosync: async with --max_policy_lag");
ABSL_FLAG(int64_t, max_policy_lag, 4,
          "learner (async): segments older than this many versions are "
          "dropped and counted");
ABSL_FLAG(int64_t, segment_length, 128,
          "learner: steps per segment its actors send (divides --horizon "
          "with --sync)");
ABSL_FLAG(std::string, listen, "127.0.0.1:0",
          "learner: HOST:PORT to serve actors on (port 0: a free one)");
ABSL_FLAG(std::string, port_file, "",
          "learner: write the bound port here once serving");
ABSL_FLAG(std::string, learner, "", "actor: the learner's HOST:PORT");
// What clients can make a learner hold; defaults from the structs that use
// them (docs/security.md explains each).
ABSL_FLAG(int64_t, max_live_actors, vantage::GatewayLimits().max_live_actors,
          "learner: registrations held at once (more: RESOURCE_EXHAUSTED)");
ABSL_FLAG(int64_t, max_envs_per_actor,
          vantage::GatewayLimits().max_envs_per_actor,
          "learner: env slots one registration may claim");
ABSL_FLAG(int64_t, max_live_env_slots,
          vantage::GatewayLimits().max_live_env_slots,
          "learner: env slots over all live registrations");
ABSL_FLAG(double, actor_expiry_s,
          absl::ToDoubleSeconds(vantage::GatewayLimits().actor_expiry),
          "learner: a registration with no open call for this long expires");
ABSL_FLAG(double, idle_stream_timeout_s,
          absl::ToDoubleSeconds(vantage::ServiceLimits().idle_stream_timeout),
          "learner: a segment stream silent for this long is cancelled");
ABSL_FLAG(double, max_abs_observation,
          vantage::ValueLimits().max_abs_observation,
          "learner: segments with a larger |observation| are refused");
ABSL_FLAG(double, max_abs_action, vantage::ValueLimits().max_abs_action,
          "learner: segments with a larger |action| are refused");
ABSL_FLAG(double, max_abs_reward, vantage::ValueLimits().max_abs_reward,
          "learner: segments with a larger |reward| are refused");
ABSL_FLAG(double, max_abs_log_prob, vantage::ValueLimits().max_abs_log_prob,
          "learner: segments with a larger |behaviour log-prob| are refused");
ABSL_FLAG(int, max_server_threads,
          vantage::LearnerServerConfig().max_server_threads,
          "learner: gRPC server threads (each open call holds one)");
ABSL_FLAG(int64_t, max_grpc_memory_mb,
          vantage::LearnerServerConfig().max_grpc_memory_bytes >> 20,
          "learner: memory gRPC may use for its buffers, MiB");
ABSL_FLAG(std::string, metrics, "",
          "learner, actor: serve Prometheus metrics on HOST:PORT (port 0: a "
          "free one, printed on stderr); empty: none");
ABSL_FLAG(std::string, name, "actor", "actor: a name for logs");
ABSL_FLAG(int, max_reconnects, -1,
          "actor: reconnection attempts (0: exit at the first failure, -1: "
          "forever)");
ABSL_FLAG(std::string, auth_token_file, "",
          "learner, actor, train (distributed): a file holding the shared "
          "token every RPC must carry; empty: none");
ABSL_FLAG(std::string, tls_cert, "",
          "learner: its TLS certificate (PEM, with --tls_key); actor: its "
          "client certificate");
ABSL_FLAG(std::string, tls_key, "",
          "learner: the private key of --tls_cert (PEM); actor: the client "
          "certificate's key");
ABSL_FLAG(std::string, tls_ca, "",
          "actor: TLS with this CA (PEM) verifying the learner; learner: "
          "clients must present a certificate this CA signed");
ABSL_FLAG(std::string, checkpoint, "",
          "rollout: a run directory or checkpoint file whose policy acts");
ABSL_FLAG(bool, stochastic, false,
          "rollout --checkpoint: sample actions instead of the mean/mode");
ABSL_FLAG(int64_t, episodes, 10, "rollout: number of episodes");
ABSL_FLAG(uint64_t, seed, 0, "rollout, train: random seed");
ABSL_FLAG(int64_t, bench_steps, 2048, "bench advantages: rollout length T");
ABSL_FLAG(int64_t, bench_streams, 16,
          "bench advantages: number of env streams");
ABSL_FLAG(int32_t, bench_clients, 4,
          "bench ingest: loopback clients streaming segments");
ABSL_FLAG(double, bench_seconds, 5.0,
          "bench ingest, bench actor: length of each timed window");

namespace vantage {
namespace {

constexpr int kUsageExitCode = 2;

using Command = std::function<int(const std::vector<std::string>& args)>;

int RunAdvantages(const std::vector<std::string>& args) {
  if (!args.empty()) {
    std::fprintf(stderr, "vantage advantages: unexpected argument '%s'\n",
                 args[0].c_str());
    return kUsageExitCode;
  }
  if (absl::GetFlag(FLAGS_example)) return RunAdvantagesExample();
  return RunAdvantagesCommand(absl::GetFlag(FLAGS_input));
}

// For commands that take no positional arguments.
int NoArguments(const char* command, const std::vector<std::string>& args) {
  if (args.empty()) return 0;
  std::fprintf(stderr, "vantage %s: unexpected argument '%s'\n", command,
               args[0].c_str());
  return kUsageExitCode;
}

int RunEnvs(const std::vector<std::string>& args) {
  if (int code = NoArguments("envs", args); code != 0) return code;
  return RunEnvsCommand();
}

int RunRollout(const std::vector<std::string>& args) {
  if (int code = NoArguments("rollout", args); code != 0) return code;
  RolloutRequest request;
  request.env = absl::GetFlag(FLAGS_env);
  request.episodes = absl::GetFlag(FLAGS_episodes);
  request.seed = absl::GetFlag(FLAGS_seed);
  request.checkpoint = absl::GetFlag(FLAGS_checkpoint);
  request.stochastic = absl::GetFlag(FLAGS_stochastic);
  return RunRolloutCommand(request);
}

// The names of the flags given on the command line (this absl version
// keeps CommandLineFlag::IsSpecifiedOnCommandLine private).
std::set<std::string>& GivenFlags() {
  static auto* given = new std::set<std::string>;
  return *given;
}

void RecordGivenFlags(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    absl::string_view arg = argv[i];
    if (arg == "--") break;
    if (!absl::ConsumePrefix(&arg, "--") && !absl::ConsumePrefix(&arg, "-")) {
      continue;
    }
    const std::string name(arg.substr(0, arg.find('=')));
    GivenFlags().insert(name);
    // --noflag sets a bool flag to false.
    if (absl::StartsWith(name, "no")) GivenFlags().insert(name.substr(2));
  }
}

// Whether a flag was set on the command line, as opposed to holding its
// default (a config file fills those).
bool Given(absl::string_view name) {
  return GivenFlags().count(std::string(name)) > 0;
}

// Appends the integers of a list flag; false (after a message) if one is not.
template <typename Repeated>
bool ParseIntegers(const char* name, const std::vector<std::string>& values,
                   Repeated& out) {
  for (const std::string& text : values) {
    int64_t value = 0;
    if (!absl::SimpleAtoi(text, &value)) {
      std::fprintf(stderr, "vantage train: --%s entry '%s' is not an integer\n",
                   name, text.c_str());
      return false;
    }
    out.Add(value);
  }
  return true;
}

// The train flags given on the command line; false after a message.
bool BuildTrainRequest(TrainRequest& request) {
  pb::RunConfig& c = request.flags;
  if (Given("mode")) c.set_mode(absl::GetFlag(FLAGS_mode));
  if (Given("env")) c.set_env(absl::GetFlag(FLAGS_env));
  if (Given("algo")) c.set_algo(absl::GetFlag(FLAGS_algo));
  if (Given("estimator")) c.set_estimator(absl::GetFlag(FLAGS_estimator));
  if (Given("rho")) c.set_rho(absl::GetFlag(FLAGS_rho));
  if (Given("ensemble") &&
      !ParseIntegers("ensemble", absl::GetFlag(FLAGS_ensemble),
                     *c.mutable_ensemble())) {
    return false;
  }
  if (Given("steps")) c.set_steps(absl::GetFlag(FLAGS_steps));
  if (Given("seed")) c.set_seed(absl::GetFlag(FLAGS_seed));
  if (Given("envs")) c.set_envs(absl::GetFlag(FLAGS_envs));
  if (Given("horizon")) c.set_horizon(absl::GetFlag(FLAGS_horizon));
  if (Given("minibatches")) c.set_minibatches(absl::GetFlag(FLAGS_minibatches));
  if (Given("epochs")) c.set_epochs(absl::GetFlag(FLAGS_epochs));
  if (Given("learning_rate")) {
    c.set_learning_rate(absl::GetFlag(FLAGS_learning_rate));
  }
  if (Given("gamma")) c.set_gamma(absl::GetFlag(FLAGS_gamma));
  if (Given("gae_lambda")) c.set_gae_lambda(absl::GetFlag(FLAGS_gae_lambda));
  if (Given("entropy_coef")) {
    c.set_entropy_coef(absl::GetFlag(FLAGS_entropy_coef));
  }
  if (Given("hidden") && !ParseIntegers("hidden", absl::GetFlag(FLAGS_hidden),
                                        *c.mutable_hidden())) {
    return false;
  }
  if (Given("scale_rewards")) {
    c.set_scale_rewards(absl::GetFlag(FLAGS_scale_rewards));
  }
  if (Given("max_kl")) c.set_max_kl(absl::GetFlag(FLAGS_max_kl));
  if (Given("checkpoint_every")) {
    c.set_checkpoint_every(absl::GetFlag(FLAGS_checkpoint_every));
  }
  if (Given("keep_checkpoints")) {
    c.set_keep_checkpoints(absl::GetFlag(FLAGS_keep_checkpoints));
  }
  if (Given("sync") || Given("nosync")) c.set_sync(absl::GetFlag(FLAGS_sync));
  if (Given("actors")) c.set_actors(absl::GetFlag(FLAGS_actors));
  if (Given("envs_per_actor")) {
    c.set_envs_per_actor(absl::GetFlag(FLAGS_envs_per_actor));
  }
  if (Given("max_policy_lag")) {
    c.set_max_policy_lag(absl::GetFlag(FLAGS_max_policy_lag));
  }
  if (Given("segment_length")) {
    c.set_segment_length(absl::GetFlag(FLAGS_segment_length));
  }
  request.config_file = absl::GetFlag(FLAGS_config);
  request.run_dir = absl::GetFlag(FLAGS_run_dir);
  request.resume = absl::GetFlag(FLAGS_resume);
  return true;
}

// The security flags, the token read from its file, checked for the side
// that uses them; false after a message.
bool BuildSecurity(const char* command, bool server,
                   SecurityOptions& security) {
  security.tls_cert_file = absl::GetFlag(FLAGS_tls_cert);
  security.tls_key_file = absl::GetFlag(FLAGS_tls_key);
  security.tls_ca_file = absl::GetFlag(FLAGS_tls_ca);
  absl::Status status = server ? ValidateServerSecurity(security)
                               : ValidateClientSecurity(security);
  if (status.ok() && !absl::GetFlag(FLAGS_auth_token_file).empty()) {
    absl::StatusOr<std::string> token =
        ReadTokenFile(absl::GetFlag(FLAGS_auth_token_file));
    if (token.ok()) {
      security.auth_token = *std::move(token);
    } else {
      status = token.status();
    }
  }
  if (status.ok()) return true;
  std::fprintf(stderr, "vantage %s: %s\n", command,
               std::string(status.message()).c_str());
  return false;
}

int RunTrain(const std::vector<std::string>& args) {
  if (int code = NoArguments("train", args); code != 0) return code;
  TrainRequest request;
  if (!BuildTrainRequest(request)) return kUsageExitCode;
  // The children read the files themselves; checked here to fail early.
  SecurityOptions security;
  if (!BuildSecurity("train", /*server=*/true, security)) return kUsageExitCode;
  request.auth_token_file = absl::GetFlag(FLAGS_auth_token_file);
  request.tls_cert = security.tls_cert_file;
  request.tls_key = security.tls_key_file;
  request.tls_ca = security.tls_ca_file;
  return RunTrainCommand(request);
}

int RunLearner(const std::vector<std::string>& args) {
  if (int code = NoArguments("learner", args); code != 0) return code;
  LearnerRequest request;
  if (!BuildTrainRequest(request.train)) return kUsageExitCode;
  request.listen = absl::GetFlag(FLAGS_listen);
  request.port_file = absl::GetFlag(FLAGS_port_file);
  request.metrics = absl::GetFlag(FLAGS_metrics);
  GatewayLimits& limits = request.limits;
  limits.max_live_actors = absl::GetFlag(FLAGS_max_live_actors);
  limits.max_envs_per_actor = absl::GetFlag(FLAGS_max_envs_per_actor);
  limits.max_live_env_slots = absl::GetFlag(FLAGS_max_live_env_slots);
  limits.actor_expiry = absl::Seconds(absl::GetFlag(FLAGS_actor_expiry_s));
  limits.values.max_abs_observation = absl::GetFlag(FLAGS_max_abs_observation);
  limits.values.max_abs_action = absl::GetFlag(FLAGS_max_abs_action);
  limits.values.max_abs_reward = absl::GetFlag(FLAGS_max_abs_reward);
  limits.values.max_abs_log_prob = absl::GetFlag(FLAGS_max_abs_log_prob);
  request.service_limits.idle_stream_timeout =
      absl::Seconds(absl::GetFlag(FLAGS_idle_stream_timeout_s));
  request.max_server_threads = absl::GetFlag(FLAGS_max_server_threads);
  request.max_grpc_memory_bytes = absl::GetFlag(FLAGS_max_grpc_memory_mb) << 20;
  if (absl::Status status = limits.Validate();
      !status.ok() ||
      !(request.service_limits.idle_stream_timeout > absl::ZeroDuration()) ||
      request.max_server_threads < 8 || request.max_grpc_memory_bytes < 1) {
    std::fprintf(stderr, "vantage learner: %s\n",
                 status.ok() ? "--idle_stream_timeout_s must be > 0, "
                               "--max_server_threads >= 8 and "
                               "--max_grpc_memory_mb >= 1"
                             : std::string(status.message()).c_str());
    return kUsageExitCode;
  }
  if (!BuildSecurity("learner", /*server=*/true, request.security)) {
    return kUsageExitCode;
  }
  return RunLearnerCommand(request);
}

int RunActor(const std::vector<std::string>& args) {
  if (int code = NoArguments("actor", args); code != 0) return code;
  RemoteActorConfig config;
  config.learner = absl::GetFlag(FLAGS_learner);
  if (Given("env")) config.env = absl::GetFlag(FLAGS_env);
  config.num_envs = absl::GetFlag(FLAGS_envs);
  config.seed = absl::GetFlag(FLAGS_seed);
  config.name = absl::GetFlag(FLAGS_name);
  config.max_reconnects = absl::GetFlag(FLAGS_max_reconnects);
  config.metrics_address = absl::GetFlag(FLAGS_metrics);
  if (!BuildSecurity("actor", /*server=*/false, config.security)) {
    return kUsageExitCode;
  }
  return RunActorCommand(config);
}

int RunBench(const std::vector<std::string>& args) {
  const std::map<std::string, std::function<int()>> benchmarks = {
      {"advantages",
       [] {
         const int64_t steps = absl::GetFlag(FLAGS_bench_steps);
         const int64_t streams = absl::GetFlag(FLAGS_bench_streams);
         if (steps < 1 || streams < 1) {
           std::fprintf(stderr,
                        "vantage bench advantages: --bench_steps and "
                        "--bench_streams must be >= 1\n");
           return kUsageExitCode;
         }
         return RunAdvantageBenchmark(steps, streams);
       }},
      {"actor",
       [] {
         // The setting unless told otherwise.
         const std::string env =
             Given("env") ? absl::GetFlag(FLAGS_env) : "HalfCheetah";
         const int envs = Given("envs") ? absl::GetFlag(FLAGS_envs) : 16;
         const double seconds = absl::GetFlag(FLAGS_bench_seconds);
         if (envs < 1 || !(seconds > 0)) {
           std::fprintf(stderr,
                        "vantage bench actor: --envs must be >= 1 and "
                        "--bench_seconds > 0\n");
           return kUsageExitCode;
         }
         return RunActorBenchmark(env, envs, seconds);
       }},
      {"env", [] { return RunEnvBenchmark(absl::GetFlag(FLAGS_env)); }},
      {"ingest",
       [] {
         const int clients = absl::GetFlag(FLAGS_bench_clients);
         const double seconds = absl::GetFlag(FLAGS_bench_seconds);
         if (clients < 1 || !(seconds > 0)) {
           std::fprintf(stderr,
                        "vantage bench ingest: --bench_clients must be >= 1 "
                        "and --bench_seconds > 0\n");
           return kUsageExitCode;
         }
         return RunIngestBenchmark(clients, seconds);
       }},
      {"learner", [] { return RunLearnerBenchmark(); }},
  };
  std::vector<std::string> names;
  for (const auto& entry : benchmarks) names.push_back(entry.first);
  if (args.size() != 1 || benchmarks.count(args[0]) == 0) {
    std::fprintf(stderr, "vantage bench: name one benchmark of: %s\n",
                 absl::StrJoin(names, ", ").c_str());
    return kUsageExitCode;
  }
  return benchmarks.at(args[0])();
}

const std::map<std::string, Command>& Commands() {
  static const auto* commands = new std::map<std::string, Command>{
      {"actor", RunActor},     {"advantages", RunAdvantages},
      {"bench", RunBench},     {"envs", RunEnvs},
      {"learner", RunLearner}, {"rollout", RunRollout},
      {"train", RunTrain},
  };
  return *commands;
}

std::string CommandNames() {
  std::vector<std::string> names;
  for (const auto& entry : Commands()) names.push_back(entry.first);
  return absl::StrJoin(names, ", ");
}

}  // namespace
}  // namespace vantage

int main(int argc, char** argv) {
  // Google Benchmark takes its own --benchmark_* flags out of argv first.
  // Interleaving the repetitions of all benchmarks spreads a noisy
  // machine's slow moments over all of them instead of skewing one ratio;
  // a later --benchmark_enable_random_interleaving=false still wins.
  std::vector<char*> args(argv, argv + argc);
  char interleave[] = "--benchmark_enable_random_interleaving=true";
  args.insert(args.begin() + 1, interleave);
  int args_count = static_cast<int>(args.size());
  benchmark::Initialize(&args_count, args.data());
  argc = args_count;
  argv = args.data();
  absl::SetProgramUsageMessage(
      "vantage <command> [flags]\n"
      "  advantages --input=FILE.json   estimates of one rollout as JSON\n"
      "  advantages --example           every estimator on a built-in rollout\n"
      "  train [--env --algo --estimator --rho --steps --seed --run_dir ...]\n"
      "                                 local PPO / A2C / TRPO training\n"
      "  train --config=FILE.json       flags from a run config file\n"
      "  train --resume=RUN_DIR         continue from the last checkpoint\n"
      "  learner --listen=HOST:PORT [--port_file=F] [train flags]\n"
      "          [--auth_token_file=F] [--tls_cert=F --tls_key=F "
      "[--tls_ca=F]]\n"
      "                                 serve actors over gRPC and train\n"
      "  actor --learner=HOST:PORT --env=NAME --envs=M\n"
      "        [--auth_token_file=F] [--tls_ca=F [--tls_cert=F --tls_key=F]]\n"
      "                                 act and stream segments to a learner\n"
      "  envs                           registered environments\n"
      "  rollout --env=NAME --episodes=N --seed=S   random-policy episodes\n"
      "  rollout --checkpoint=RUN_DIR [--episodes=N] [--stochastic]\n"
      "                                 the trained policy's episodes\n"
      "  bench advantages               path ensemble vs GAE benchmark\n"
      "  bench env --env=NAME           env layer vs raw physics benchmark\n"
      "  bench learner                  PPO update vs a bare LibTorch loop\n"
      "  bench ingest                   learner ingest capacity in actors\n"
      "  bench actor --env=N --envs=M   streaming actor vs raw physics\n");
  vantage::RecordGivenFlags(argc, argv);
  const std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  if (positional.size() < 2) {
    std::fprintf(stderr, "%s", absl::ProgramUsageMessage().data());
    return vantage::kUsageExitCode;
  }
  const std::string name = positional[1];
  const auto& commands = vantage::Commands();
  auto command = commands.find(name);
  if (command == commands.end()) {
    std::fprintf(stderr, "vantage: unknown command '%s'; commands: %s\n",
                 name.c_str(), vantage::CommandNames().c_str());
    return vantage::kUsageExitCode;
  }
  return command->second(
      std::vector<std::string>(positional.begin() + 2, positional.end()));
}
