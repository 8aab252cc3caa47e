#include "deploy/launcher.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "deploy/run_config.h"
#include "deploy/run_directory.h"
#include "learner/checkpoint.h"

namespace vantage {
namespace {

// Runs this binary with `args` as a child process.
absl::StatusOr<pid_t> Spawn(const std::vector<std::string>& args) {
  std::error_code error;
  const std::string self =
      std::filesystem::read_symlink("/proc/self/exe", error).string();
  if (error) return absl::InternalError("cannot find this binary");
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(self.c_str()));
  for (const std::string& arg : args) {
    argv.push_back(const_cast<char*>(arg.c_str()));
  }
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return absl::InternalError("fork failed");
  if (pid == 0) {
    execv(self.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

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

// Waits for the learner `pid` to write its port to `port_file`; empty if
// it ended first (`status` says how) or `stop` was set.
std::string WaitForPort(pid_t pid, const std::string& port_file,
                        const std::atomic<bool>& stop, int& status) {
  while (!stop) {
    if (waitpid(pid, &status, WNOHANG) == pid) return "";
    std::ifstream file(port_file);
    std::string line;
    if (std::getline(file, line) && !line.empty()) return line;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return "";
}

// A learner that died (not one that refused its flags, exit code 2) can be
// restarted when the run has a checkpoint to continue from.
bool CanResume(const LaunchConfig& config, int status) {
  if (config.run_dir.empty()) return false;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 2) return false;
  absl::StatusOr<RunDirectory> run = RunDirectory::Open(config.run_dir);
  return run.ok() && !ListCheckpoints(run->checkpoint_directory()).empty();
}

}  // namespace

absl::Status RunDistributedTraining(const LaunchConfig& config,
                                    const std::atomic<bool>& stop) {
  const pb::RunConfig& run = config.run_config;
  std::error_code error;
  std::filesystem::create_directories(config.work_dir, error);
  const std::string config_path = config.work_dir + "/launch_config.json";
  const std::string port_file = config.work_dir + "/learner.port";
  {
    std::ofstream file(config_path, std::ios::trunc);
    file << RunConfigToJson(run);
    if (!file.flush()) {
      return absl::InternalError(absl::StrCat("cannot write ", config_path));
    }
  }
  const std::vector<std::string> security_args = SecurityArgs(config);
  // A resumed learner continues the run directory as its config.json says,
  // on the port the actors already know.
  auto start_learner = [&](bool resume,
                           const std::string& port) -> absl::StatusOr<pid_t> {
    std::filesystem::remove(port_file, error);
    std::vector<std::string> args = {"learner", "--listen=127.0.0.1:" + port,
                                     "--port_file=" + port_file};
    if (resume) {
      args.push_back("--resume=" + config.run_dir);
    } else {
      args.push_back("--config=" + config_path);
      if (!config.run_dir.empty())
        args.push_back("--run_dir=" + config.run_dir);
    }
    args.insert(args.end(), security_args.begin(), security_args.end());
    return Spawn(args);
  };
  absl::StatusOr<pid_t> learner = start_learner(config.resume, "0");
  if (!learner.ok()) return learner.status();
  int learner_status = 0;
  const std::string port =
      WaitForPort(*learner, port_file, stop, learner_status);
  if (port.empty()) {
    if (stop) {
      Terminate({*learner}, std::chrono::seconds(10));
      return absl::OkStatus();
    }
    return absl::InternalError(absl::StrCat(
        "the learner ended before serving (", Describe(learner_status), ")"));
  }
  std::fprintf(stderr, "launcher: learner on port %s, starting %d actors\n",
               port.c_str(), run.distributed().actors());

  auto start_actor = [&](int i) {
    std::vector<std::string> args = {
        "actor",
        "--learner=127.0.0.1:" + port,
        "--env=" + run.training().env(),
        absl::StrCat("--envs=", run.distributed().envs_per_actor()),
        absl::StrCat("--seed=", run.training().seed() + i),
        absl::StrCat("--name=actor-", i)};
    args.insert(args.end(), security_args.begin(), security_args.end());
    return Spawn(args);
  };
  std::vector<pid_t> actors(run.distributed().actors(), -1);
  auto everyone = [&] {
    std::vector<pid_t> all = actors;
    all.push_back(*learner);
    return all;
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
  absl::Status result;
  while (true) {
    if (stop) {
      // Everyone gets the signal; the learner writes its last checkpoint.
      Terminate(everyone(), std::chrono::seconds(30));
      return absl::OkStatus();
    }
    int status = 0;
    const pid_t done = waitpid(-1, &status, WNOHANG);
    if (done == *learner) {
      if (WIFEXITED(status) && WEXITSTATUS(status) == 0) break;
      if (learner_restarts >= config.max_learner_restarts ||
          !CanResume(config, status)) {
        *learner = -1;
        result = absl::InternalError(
            absl::StrCat("the learner failed (", Describe(status), ")"));
        break;
      }
      // The actors keep their environments and reconnect by themselves.
      ++learner_restarts;
      std::fprintf(stderr,
                   "launcher: the learner ended (%s); resuming it from the "
                   "run's last checkpoint\n",
                   Describe(status).c_str());
      learner = start_learner(/*resume=*/true, port);
      if (!learner.ok()) {
        Terminate(actors, std::chrono::seconds(10));
        return learner.status();
      }
      if (WaitForPort(*learner, port_file, stop, learner_status).empty() &&
          !stop) {
        *learner = -1;
        result = absl::InternalError(
            absl::StrCat("the resumed learner ended before serving (",
                         Describe(learner_status), ")"));
        break;
      }
      continue;
    }
    for (int i = 0; done > 0 && i < run.distributed().actors(); ++i) {
      if (actors[i] != done) continue;
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
    if (!result.ok()) {
      Terminate(everyone(), std::chrono::seconds(30));
      return result;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  Terminate(actors, std::chrono::seconds(10));
  return result;
}

}  // namespace vantage
