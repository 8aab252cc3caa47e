#include "tests/fakes/learner_process.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {

// Starts `vantage learner <args>` and waits for its port file.
Learner StartLearner(const std::string& args) {
  Learner learner;
  const std::string port_file = TempPath("port");
  std::filesystem::remove(port_file);  // a stale one from an earlier run
  learner.out = TempPath("learner.out");
  learner.err = TempPath("learner.err");
  learner.pid = StartVantage(
      "learner --listen=127.0.0.1:0 --port_file=" + port_file + " " + args,
      learner.out, learner.err);
  for (int i = 0; i < 600 && !std::filesystem::exists(port_file); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  learner.port = ReadFile(port_file);
  while (!learner.port.empty() && learner.port.back() == '\n') {
    learner.port.pop_back();
  }
  EXPECT_FALSE(learner.port.empty()) << ReadFile(learner.err);
  return learner;
}

// The port a process printed as "<who>: metrics on port N".
int MetricsPort(const std::string& err_path, const std::string& who) {
  const std::string marker = who + ": metrics on port ";
  for (int i = 0; i < 600; ++i) {
    const std::string err = ReadFile(err_path);
    const size_t at = err.find(marker);
    int port = 0;
    if (at != std::string::npos &&
        absl::SimpleAtoi(err.substr(at + marker.size(),
                                    err.find('\n', at) - at - marker.size()),
                         &port)) {
      return port;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

// The value of an unlabelled sample in Prometheus text.
double Sample(const std::string& text, const std::string& name) {
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    if (absl::ConsumePrefix(&line, name + " ")) {
      double value = 0;
      if (absl::SimpleAtod(line, &value)) return value;
    }
  }
  return -1;
}

int64_t ProcessStatusField(int pid, const std::string& field) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(file, line)) {
    absl::string_view rest = line;
    if (!absl::ConsumePrefix(&rest, field + ":")) continue;
    const std::vector<std::string> words =
        absl::StrSplit(absl::StripAsciiWhitespace(rest), ' ');
    int64_t value = 0;
    if (!absl::SimpleAtoi(words[0], &value)) return -1;
    return words.size() > 1 && words[1] == "kB" ? value * 1024 : value;
  }
  return -1;
}

// The children of `parent` whose command line contains `word`.
std::vector<int> ChildrenRunning(int parent, const std::string& word) {
  std::vector<int> pids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    int pid = 0;
    if (!absl::SimpleAtoi(entry.path().filename().string(), &pid)) continue;
    const std::string stat = ReadFile(entry.path().string() + "/stat");
    // Field 4 of /proc/PID/stat is the parent (after "(comm)").
    const size_t close = stat.rfind(')');
    if (close == std::string::npos) continue;
    const std::vector<std::string> fields =
        absl::StrSplit(stat.substr(close + 2), ' ');
    if (fields.size() < 2 || fields[1] != std::to_string(parent)) continue;
    std::string command = ReadFile(entry.path().string() + "/cmdline");
    std::replace(command.begin(), command.end(), '\0', ' ');
    if (command.find(word) != std::string::npos) pids.push_back(pid);
  }
  return pids;
}

}  // namespace vantage
