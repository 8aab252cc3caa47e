#include "deploy/run/launcher.h"

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
#include "common/util/split_mix.h"
#include "deploy/observe/scrape_targets.h"
#include "deploy/run/run_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/checkpoint/checkpoint_files.h"
#include "learner/run/run_directory.h"

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

// The processes of a run on one machine, started and watched: the learners
// (Start), then the actors (StartActors), then Supervise until the learners
// finish, one fails for good or a stop is requested.
class Supervisor {
 public:
  Supervisor(const LaunchConfig& config, const std::atomic<bool>& stop)
      : config_(config),
        run_(config.run_config),
        stop_(stop),
        learner_count_(std::max(1, run_.distributed().learners())),
        actor_count_(run_.distributed().actors()),
        config_path_(config.work_dir + "/launch_config.json"),
        security_args_(SecurityArgs(config)),
        metrics_(config, learner_count_, actor_count_),
        ports_(learner_count_, "0"),
        learners_(learner_count_, -1),
        finished_(learner_count_, false),
        actors_(actor_count_, -1),
        actor_lives_(actor_count_, 0) {}

  absl::Status Run();

 private:
  // How the loop goes on after a learner's exit.
  enum class Next { kWatch, kFinished, kFailed };

  absl::Status WriteLaunchConfig() const;
  std::string PortFile(int rank) const {
    return rank == 0
               ? config_.work_dir + "/learner.port"
               : absl::StrCat(config_.work_dir, "/learner-", rank, ".port");
  }
  std::string LearnerName(int rank) const {
    return learner_count_ > 1 ? absl::StrCat("learner ", rank)
                              : std::string("the learner");
  }
  std::vector<std::string> LearnerArgs(int rank, bool resume,
                                       const std::string& rendezvous);
  // A resumed learner continues the run directory as its config.json says,
  // on the port its actors already know. Replicas meet at a rendezvous on
  // a port fresh for every start, so a restart never meets the old group.
  // Returns once every learner serves (or a stop is requested).
  absl::Status StartLearners(bool resume);
  // Actor i serves learner i mod K, so each learner gets an equal share.
  absl::StatusOr<pid_t> StartActor(int i);
  absl::Status StartActors();
  std::vector<pid_t> Everyone() const {
    std::vector<pid_t> all = actors_;
    all.insert(all.end(), learners_.begin(), learners_.end());
    return all;
  }
  // Until the learners finish the run (OK), one fails for good, or a stop.
  absl::Status Supervise();
  Next OnLearnerExit(int rank, int status, absl::Status& result);
  // An actor that ended is restarted unless the run is over for it.
  absl::Status OnActorExit(int i, int status);

  const LaunchConfig& config_;
  const pb::RunConfig& run_;
  const std::atomic<bool>& stop_;
  const int learner_count_;
  const int actor_count_;
  const std::string config_path_;
  const std::vector<std::string> security_args_;
  MetricsPlan metrics_;
  // Learner ranks' gRPC ports ("0" until first bound: the actors keep them
  // across restarts) and processes, and the ranks that finished the run
  // (exit code 0).
  std::vector<std::string> ports_;
  std::vector<pid_t> learners_;
  std::vector<bool> finished_;
  std::vector<pid_t> actors_;
  std::vector<int> actor_lives_;  // each actor's restarts so far
  int actor_restarts_ = 0;
  int learner_restarts_ = 0;
};

absl::Status Supervisor::WriteLaunchConfig() const {
  std::error_code error;
  std::filesystem::create_directories(config_.work_dir, error);
  std::ofstream file(config_path_, std::ios::trunc);
  file << RunConfigToJson(run_);
  if (!file.flush()) {
    return absl::InternalError(absl::StrCat("cannot write ", config_path_));
  }
  return absl::OkStatus();
}

std::vector<std::string> Supervisor::LearnerArgs(
    int rank, bool resume, const std::string& rendezvous) {
  std::vector<std::string> args = {"learner",
                                   "--listen=127.0.0.1:" + ports_[rank],
                                   "--port_file=" + PortFile(rank)};
  if (learner_count_ > 1) {
    args.push_back(absl::StrCat("--rank=", rank));
    args.push_back("--rendezvous=" + rendezvous);
  }
  if (resume) {
    args.push_back("--resume=" + config_.run_dir);
  } else {
    args.push_back("--config=" + config_path_);
    if (!config_.run_dir.empty())
      args.push_back("--run_dir=" + config_.run_dir);
  }
  args.insert(args.end(), security_args_.begin(), security_args_.end());
  args.insert(args.end(), config_.learner_args.begin(),
              config_.learner_args.end());
  const std::vector<std::string> metrics_args = metrics_.LearnerArgs(rank);
  args.insert(args.end(), metrics_args.begin(), metrics_args.end());
  return args;
}

absl::Status Supervisor::StartLearners(bool resume) {
  std::string rendezvous;
  if (learner_count_ > 1) {
    absl::StatusOr<int> port = FreeLoopbackPort();
    if (!port.ok()) return port.status();
    rendezvous = absl::StrCat("127.0.0.1:", *port);
  }
  std::vector<std::string> port_files;
  for (int rank = 0; rank < learner_count_; ++rank) {
    port_files.push_back(PortFile(rank));
    std::error_code error;
    std::filesystem::remove(port_files.back(), error);
    absl::StatusOr<pid_t> pid =
        SpawnSelf(LearnerArgs(rank, resume, rendezvous));
    if (!pid.ok()) return pid.status();
    learners_[rank] = *pid;
  }
  int status = 0;
  const int ended = WaitForPorts(learners_, port_files, stop_, ports_, status);
  if (ended < 0) return absl::OkStatus();
  learners_[ended] = -1;
  return absl::InternalError(absl::StrCat(
      LearnerName(ended), " ended before serving (", Describe(status), ")"));
}

absl::StatusOr<pid_t> Supervisor::StartActor(int i) {
  std::vector<std::string> args = {
      "actor",
      "--learner=127.0.0.1:" + ports_[i % learner_count_],
      "--env=" + run_.training().env(),
      "--env_kwargs=" + run_.training().env_kwargs(),
      absl::StrCat("--envs=", run_.distributed().envs_per_actor()),
      absl::StrCat("--seed=",
                   ActorLifeSeed(run_.training().seed(), i, actor_lives_[i])),
      absl::StrCat("--name=actor-", i)};
  args.insert(args.end(), security_args_.begin(), security_args_.end());
  const std::vector<std::string> metrics_args = metrics_.ActorArgs(i);
  args.insert(args.end(), metrics_args.begin(), metrics_args.end());
  return SpawnSelf(args);
}

absl::Status Supervisor::StartActors() {
  const std::string serving =
      learner_count_ > 1 ? absl::StrCat(learner_count_, " learners on ports ",
                                        absl::StrJoin(ports_, ", "))
                         : absl::StrCat("learner on port ", ports_[0]);
  std::fprintf(stderr, "launcher: %s, starting %d actors\n", serving.c_str(),
               actor_count_);
  for (int i = 0; i < actor_count_; ++i) {
    absl::StatusOr<pid_t> pid = StartActor(i);
    if (!pid.ok()) return pid.status();
    actors_[i] = *pid;
  }
  return absl::OkStatus();
}

Supervisor::Next Supervisor::OnLearnerExit(int rank, int status,
                                           absl::Status& result) {
  learners_[rank] = -1;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    finished_[rank] = true;
    return std::all_of(finished_.begin(), finished_.end(),
                       [](bool f) { return f; })
               ? Next::kFinished
               : Next::kWatch;
  }
  const std::string who = LearnerName(rank);
  if (learner_restarts_ >= config_.max_learner_restarts ||
      !CanResume(config_, status)) {
    result = absl::InternalError(
        absl::StrCat(who, " failed (", Describe(status), ")"));
    return Next::kFailed;
  }
  // The actors keep their environments and reconnect by themselves;
  // replicas only ever train together, so all restart.
  ++learner_restarts_;
  std::fprintf(stderr,
               "launcher: %s ended (%s); resuming %s from the run's last "
               "checkpoint\n",
               who.c_str(), Describe(status).c_str(),
               learner_count_ > 1 ? "every learner" : "it");
  Terminate(learners_, std::chrono::seconds(30));
  std::fill(finished_.begin(), finished_.end(), false);
  if (absl::Status restarted = StartLearners(/*resume=*/true);
      !restarted.ok()) {
    result = absl::InternalError(absl::StrCat(
        "resuming from the last checkpoint failed: ", restarted.message()));
    return Next::kFailed;
  }
  return Next::kWatch;
}

absl::Status Supervisor::OnActorExit(int i, int status) {
  // Exit 0: the learner told it the run is complete; the learner's own exit
  // follows.
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    actors_[i] = -1;
    return absl::OkStatus();
  }
  if (actor_restarts_ >= config_.max_actor_restarts) {
    actors_[i] = -1;
    return absl::InternalError(
        absl::StrCat("actor ", i, " ended (", Describe(status), ") after ",
                     actor_restarts_, " restarts; giving up"));
  }
  ++actor_restarts_;
  ++actor_lives_[i];
  std::fprintf(stderr,
               "launcher: actor %d ended (%s); restarting it (life %d, env "
               "seed %llu)\n",
               i, Describe(status).c_str(), actor_lives_[i] + 1,
               static_cast<unsigned long long>(
                   ActorLifeSeed(run_.training().seed(), i, actor_lives_[i])));
  absl::StatusOr<pid_t> pid = StartActor(i);
  actors_[i] = pid.ok() ? *pid : -1;
  return absl::OkStatus();
}

absl::Status Supervisor::Supervise() {
  auto last_refresh = std::chrono::steady_clock::now();
  while (!stop_) {
    if (std::chrono::steady_clock::now() - last_refresh >
        std::chrono::milliseconds(250)) {
      metrics_.Refresh();
      last_refresh = std::chrono::steady_clock::now();
    }
    int status = 0;
    const pid_t done = waitpid(-1, &status, WNOHANG);
    if (done <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    if (const auto learner =
            std::find(learners_.begin(), learners_.end(), done);
        learner != learners_.end()) {
      absl::Status result;
      switch (OnLearnerExit(static_cast<int>(learner - learners_.begin()),
                            status, result)) {
        case Next::kFinished:
          return absl::OkStatus();
        case Next::kFailed:
          return result;
        case Next::kWatch:
          continue;
      }
    }
    if (const auto actor = std::find(actors_.begin(), actors_.end(), done);
        actor != actors_.end()) {
      if (absl::Status actor_status =
              OnActorExit(static_cast<int>(actor - actors_.begin()), status);
          !actor_status.ok()) {
        return actor_status;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return absl::OkStatus();
}

absl::Status Supervisor::Run() {
  if (absl::Status status = WriteLaunchConfig(); !status.ok()) return status;
  if (absl::Status started = StartLearners(config_.resume); !started.ok()) {
    Terminate(learners_, std::chrono::seconds(10));
    return started;
  }
  if (stop_) {
    Terminate(learners_, std::chrono::seconds(10));
    return absl::OkStatus();
  }
  if (absl::Status started = StartActors(); !started.ok()) {
    Terminate(Everyone(), std::chrono::seconds(10));
    return started;
  }
  // Stopped (Supervise returns OK then): everyone gets the signal, and rank
  // 0 writes the last checkpoint.
  const absl::Status result = Supervise();
  Terminate(Everyone(), std::chrono::seconds(30));
  if (result.ok()) metrics_.Clear();
  return result;
}

}  // namespace

uint64_t ActorLifeSeed(uint64_t run_seed, int actor, int life) {
  const uint64_t first = run_seed + static_cast<uint64_t>(actor);
  return life == 0 ? first
                   : SplitMixSeed(first, static_cast<uint64_t>(life - 1));
}

absl::Status RunDistributedTraining(const LaunchConfig& config,
                                    const std::atomic<bool>& stop) {
  Supervisor supervisor(config, stop);
  return supervisor.Run();
}

}  // namespace vantage
