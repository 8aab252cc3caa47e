#include "deploy/launcher.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"
#include "common/metrics/metrics_endpoint.h"
#include "common/net/loopback_port.h"
#include "common/net/port_file.h"
#include "common/util/self_process.h"
#include "deploy/run_config.h"
#include "deploy/run_directory.h"
#include "deploy/scrape_targets.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/checkpoint_files.h"

namespace vantage {
namespace {

std::string Describe(int status) {
  if (WIFEXITED(status)) return absl::StrCat("exit code ", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return absl::StrCat("signal ", WTERMSIG(status));
  return "unknown status";
}

// SIGTERM, then SIGKILL after `grace`.
void Terminate(const std::vector<pid_t>& pids, std::chrono::seconds grace) {
  for (pid_t pid : pids) {
    if (pid > 0) kill(pid, SIGTERM);
  }
  const auto deadline = std::chrono::steady_clock::now() + grace;
  for (pid_t pid : pids) {
    if (pid <= 0) continue;
    while (waitpid(pid, nullptr, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
}

// The security flags both children get.
std::vector<std::string> SecurityArgs(const LaunchConfig& config) {
  std::vector<std::string> args;
  auto add = [&](const char* flag, const std::string& value) {
    if (!value.empty()) args.push_back(absl::StrCat("--", flag, "=", value));
  };
  add("auth_token_file", config.auth_token_file);
  add("tls_cert", config.tls_cert);
  add("tls_key", config.tls_key);
  add("tls_ca", config.tls_ca);
  return args;
}

// Waits for every learner (`pids`, by rank) to write its port to its
// `port_files` entry, into `ports`. Returns -1 once all have (or when
// `stop` is set), else the rank of the first that ended before (`status`
// says how): replicas wait for each other before serving, so one that
// ends must not leave the launcher waiting for the others' timeout.
int WaitForPorts(const std::vector<pid_t>& pids,
                 const std::vector<std::string>& port_files,
                 const std::atomic<bool>& stop, std::vector<std::string>& ports,
                 int& status) {
  std::vector<bool> serving(pids.size(), false);
  size_t waiting = pids.size();
  while (!stop && waiting > 0) {
    for (size_t rank = 0; rank < pids.size(); ++rank) {
      if (serving[rank]) continue;
      if (const std::optional<int> port = ReadPortFile(port_files[rank]);
          port.has_value()) {
        ports[rank] = absl::StrCat(*port);
        serving[rank] = true;
        --waiting;
      } else if (waitpid(pids[rank], &status, WNOHANG) == pids[rank]) {
        return static_cast<int>(rank);
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return -1;
}

// A learner that died (not one that refused its flags, exit code 2) can be
// restarted when the run has a checkpoint to continue from.
bool CanResume(const LaunchConfig& config, int status) {
  if (config.run_dir.empty()) return false;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 2) return false;
  absl::StatusOr<RunDirectory> run = RunDirectory::Open(config.run_dir);
  return run.ok() && !ListCheckpoints(run->checkpoint_directory()).empty();
}

// Where each process of a run serves its metrics, and the scrape targets
// file that tells Prometheus.
class MetricsPlan {
 public:
  MetricsPlan(const LaunchConfig& config, int learners, int actors)
      : enabled_(!config.metrics_address.empty()), learners_(learners) {
    if (!enabled_) return;
    const std::string address = ResolveMetricsAddress(config.metrics_address);
    const size_t colon = address.rfind(':');
    host_ = address.substr(0, colon);
    if (colon == std::string::npos ||
        !absl::SimpleAtoi(address.substr(colon + 1), &base_port_)) {
      base_port_ = 0;
    }
    targets_path_ =
        absl::StrCat(config.run_dir.empty() ? config.work_dir : config.run_dir,
                     "/", kScrapeTargetsFile);
    const pb::RunConfig& run = config.run_config;
    common_labels_ = {{"run", config.run_dir.empty()
                                  ? std::string("")
                                  : std::filesystem::absolute(config.run_dir)
                                        .lexically_normal()
                                        .string()},
                      {"env", run.training().env()},
                      {"algo", AlgorithmNameOf(run)},
                      {"estimator", run.advantage().estimator()}};
    for (int rank = 0; rank < learners; ++rank) {
      processes_.push_back(
          {absl::StrCat(config.work_dir, "/learner-", rank, ".metrics.port"),
           {{"role", "learner"}, {"rank", absl::StrCat(rank)}}});
    }
    for (int i = 0; i < actors; ++i) {
      processes_.push_back(
          {absl::StrCat(config.work_dir, "/actor-", i, ".metrics.port"),
           {{"role", "actor"}, {"actor", absl::StrCat(i)}}});
    }
  }

  // The flags that make learner `rank` (or actor `index`) serve metrics;
  // its old port file goes first, so a restart is seen when it serves.
  std::vector<std::string> LearnerArgs(int rank) { return Args(rank); }
  std::vector<std::string> ActorArgs(int index) {
    return Args(learners_ + index);
  }

  // Rewrites the targets file if a process serves on a port it does not
  // list yet (called often: it only reads small files).
  void Refresh() {
    if (!enabled_) return;
    std::vector<ScrapeTarget> targets;
    bool changed = false;
    for (Process& process : processes_) {
      const std::optional<int> port = ReadPortFile(process.port_file);
      if (port.has_value() && *port != process.port) {
        process.port = *port;
        changed = true;
      }
      if (process.port <= 0) continue;
      ScrapeTarget target{ScrapeAddress(host_, process.port), common_labels_};
      target.labels.insert(process.labels.begin(), process.labels.end());
      targets.push_back(std::move(target));
    }
    if (changed) Write(targets);
  }

  // Nothing to scrape any more: the run ended or was stopped.
  void Clear() {
    if (enabled_) Write({});
  }

 private:
  struct Process {
    std::string port_file;
    std::map<std::string, std::string> labels;
    int port = 0;  // listed in the targets file (0: not yet)
  };

  std::vector<std::string> Args(int index) {
    if (!enabled_) return {};
    std::error_code error;
    std::filesystem::remove(processes_[index].port_file, error);
    const int port = base_port_ == 0 ? 0 : base_port_ + index;
    return {absl::StrCat("--metrics=", host_, ":", port),
            "--metrics_port_file=" + processes_[index].port_file};
  }

  void Write(const std::vector<ScrapeTarget>& targets) {
    if (absl::Status status = WriteScrapeTargets(targets_path_, targets);
        !status.ok()) {
      std::fprintf(stderr, "launcher: %s\n",
                   std::string(status.message()).c_str());
    } else if (!announced_) {
      announced_ = true;
      std::fprintf(stderr, "launcher: Prometheus scrape targets in %s\n",
                   targets_path_.c_str());
    }
  }

  const bool enabled_;
  const int learners_;
  std::string host_;
  int base_port_ = 0;
  std::string targets_path_;
  std::map<std::string, std::string> common_labels_;
  std::vector<Process> processes_;
  bool announced_ = false;
};

}  // namespace

absl::Status RunDistributedTraining(const LaunchConfig& config,
                                    const std::atomic<bool>& stop) {
  const pb::RunConfig& run = config.run_config;
  const int learner_count = std::max(1, run.distributed().learners());
  std::error_code error;
  std::filesystem::create_directories(config.work_dir, error);
  const std::string config_path = config.work_dir + "/launch_config.json";
  {
    std::ofstream file(config_path, std::ios::trunc);
    file << RunConfigToJson(run);
    if (!file.flush()) {
      return absl::InternalError(absl::StrCat("cannot write ", config_path));
    }
  }
  const auto port_file = [&](int rank) {
    return rank == 0
               ? config.work_dir + "/learner.port"
               : absl::StrCat(config.work_dir, "/learner-", rank, ".port");
  };
  const std::vector<std::string> security_args = SecurityArgs(config);
  MetricsPlan metrics(config, learner_count, run.distributed().actors());
  // Learner ranks' gRPC ports ("0" until first bound: the actors keep
  // them across restarts) and processes.
  std::vector<std::string> ports(learner_count, "0");
  std::vector<pid_t> learners(learner_count, -1);
  // A resumed learner continues the run directory as its config.json says,
  // on the port its actors already know. Replicas meet at a rendezvous on
  // a port fresh for every start, so a restart never meets the old group.
  auto start_learners = [&](bool resume) -> absl::Status {
    std::string rendezvous;
    if (learner_count > 1) {
      absl::StatusOr<int> port = FreeLoopbackPort();
      if (!port.ok()) return port.status();
      rendezvous = absl::StrCat("127.0.0.1:", *port);
    }
    for (int rank = 0; rank < learner_count; ++rank) {
      std::filesystem::remove(port_file(rank), error);
      std::vector<std::string> args = {"learner",
                                       "--listen=127.0.0.1:" + ports[rank],
                                       "--port_file=" + port_file(rank)};
      if (learner_count > 1) {
        args.push_back(absl::StrCat("--rank=", rank));
        args.push_back("--rendezvous=" + rendezvous);
      }
      if (resume) {
        args.push_back("--resume=" + config.run_dir);
      } else {
        args.push_back("--config=" + config_path);
        if (!config.run_dir.empty())
          args.push_back("--run_dir=" + config.run_dir);
      }
      args.insert(args.end(), security_args.begin(), security_args.end());
      args.insert(args.end(), config.learner_args.begin(),
                  config.learner_args.end());
      const std::vector<std::string> metrics_args = metrics.LearnerArgs(rank);
      args.insert(args.end(), metrics_args.begin(), metrics_args.end());
      absl::StatusOr<pid_t> pid = SpawnSelf(args);
      if (!pid.ok()) return pid.status();
      learners[rank] = *pid;
    }
    std::vector<std::string> port_files;
    for (int rank = 0; rank < learner_count; ++rank) {
      port_files.push_back(port_file(rank));
    }
    int status = 0;
    const int ended = WaitForPorts(learners, port_files, stop, ports, status);
    if (ended < 0) return absl::OkStatus();
    learners[ended] = -1;
    return absl::InternalError(
        absl::StrCat(learner_count > 1 ? absl::StrCat("learner ", ended)
                                       : std::string("the learner"),
                     " ended before serving (", Describe(status), ")"));
  };
  std::vector<pid_t> actors(run.distributed().actors(), -1);
  auto everyone = [&] {
    std::vector<pid_t> all = actors;
    all.insert(all.end(), learners.begin(), learners.end());
    return all;
  };
  if (absl::Status started = start_learners(config.resume); !started.ok()) {
    Terminate(learners, std::chrono::seconds(10));
    return started;
  }
  if (stop) {
    Terminate(learners, std::chrono::seconds(10));
    return absl::OkStatus();
  }
  const std::string serving =
      learner_count > 1 ? absl::StrCat(learner_count, " learners on ports ",
                                       absl::StrJoin(ports, ", "))
                        : absl::StrCat("learner on port ", ports[0]);
  std::fprintf(stderr, "launcher: %s, starting %d actors\n", serving.c_str(),
               run.distributed().actors());

  // Actor i serves learner i mod K, so each learner gets an equal share.
  auto start_actor = [&](int i) {
    std::vector<std::string> args = {
        "actor",
        "--learner=127.0.0.1:" + ports[i % learner_count],
        "--env=" + run.training().env(),
        absl::StrCat("--envs=", run.distributed().envs_per_actor()),
        absl::StrCat("--seed=", run.training().seed() + i),
        absl::StrCat("--name=actor-", i)};
    args.insert(args.end(), security_args.begin(), security_args.end());
    const std::vector<std::string> metrics_args = metrics.ActorArgs(i);
    args.insert(args.end(), metrics_args.begin(), metrics_args.end());
    return SpawnSelf(args);
  };
  for (int i = 0; i < run.distributed().actors(); ++i) {
    absl::StatusOr<pid_t> pid = start_actor(i);
    if (!pid.ok()) {
      Terminate(everyone(), std::chrono::seconds(10));
      return pid.status();
    }
    actors[i] = *pid;
  }

  int actor_restarts = 0;
  int learner_restarts = 0;
  // Ranks whose learner finished the run (exit code 0).
  std::vector<bool> finished(learner_count, false);
  absl::Status result;
  auto last_refresh = std::chrono::steady_clock::now();
  while (true) {
    if (stop) {
      // Everyone gets the signal; rank 0 writes the last checkpoint.
      Terminate(everyone(), std::chrono::seconds(30));
      metrics.Clear();
      return absl::OkStatus();
    }
    if (std::chrono::steady_clock::now() - last_refresh >
        std::chrono::milliseconds(250)) {
      metrics.Refresh();
      last_refresh = std::chrono::steady_clock::now();
    }
    int status = 0;
    const pid_t done = waitpid(-1, &status, WNOHANG);
    const auto learner = std::find(learners.begin(), learners.end(), done);
    if (done > 0 && learner != learners.end()) {
      const int rank = static_cast<int>(learner - learners.begin());
      *learner = -1;
      if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        finished[rank] = true;
        if (std::all_of(finished.begin(), finished.end(),
                        [](bool f) { return f; })) {
          break;
        }
        continue;
      }
      const std::string who =
          learner_count > 1 ? absl::StrCat("learner ", rank) : "the learner";
      if (learner_restarts >= config.max_learner_restarts ||
          !CanResume(config, status)) {
        result = absl::InternalError(
            absl::StrCat(who, " failed (", Describe(status), ")"));
        break;
      }
      // The actors keep their environments and reconnect by themselves;
      // replicas only ever train together, so all restart.
      ++learner_restarts;
      std::fprintf(stderr,
                   "launcher: %s ended (%s); resuming %s from the run's last "
                   "checkpoint\n",
                   who.c_str(), Describe(status).c_str(),
                   learner_count > 1 ? "every learner" : "it");
      Terminate(learners, std::chrono::seconds(30));
      std::fill(finished.begin(), finished.end(), false);
      if (absl::Status restarted = start_learners(/*resume=*/true);
          !restarted.ok()) {
        result = absl::InternalError(absl::StrCat(
            "resuming from the last checkpoint failed: ", restarted.message()));
        break;
      }
      continue;
    }
    for (int i = 0; done > 0 && i < run.distributed().actors(); ++i) {
      if (actors[i] != done) continue;
      // Exit 0: the learner told it the run is complete; the learner's own
      // exit follows.
      if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        actors[i] = -1;
        break;
      }
      if (actor_restarts >= config.max_actor_restarts) {
        actors[i] = -1;
        result = absl::InternalError(
            absl::StrCat("actor ", i, " ended (", Describe(status), ") after ",
                         actor_restarts, " restarts; giving up"));
        break;
      }
      ++actor_restarts;
      std::fprintf(stderr, "launcher: actor %d ended (%s); restarting it\n", i,
                   Describe(status).c_str());
      absl::StatusOr<pid_t> pid = start_actor(i);
      actors[i] = pid.ok() ? *pid : -1;
    }
    if (!result.ok()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  Terminate(everyone(), std::chrono::seconds(30));
  if (result.ok()) metrics.Clear();
  return result;
}

}  // namespace vantage
