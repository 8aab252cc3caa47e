#include "tests/deploy/cli/run_vantage.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"

namespace vantage {

std::string ReadFile(const std::string& path) {
  std::ifstream file(path);
  std::stringstream contents;
  contents << file.rdbuf();
  return contents.str();
}

std::string TempPath(const std::string& name) {
  static int counter = 0;
  // The process id keeps files of an earlier run (a stale port file, an
  // old log) from being taken for this one's.
  return absl::StrCat(
      ::testing::TempDir(), "/vantage_",
      ::testing::UnitTest::GetInstance()->current_test_info()->name(), "_",
      getpid(), "_", counter++, "_", name);
}

std::string FreshDirectory(const std::string& name) {
  const std::string path = TempPath(name);
  std::filesystem::remove_all(path);
  return path;
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  std::ofstream(path) << text;
  return path;
}

int StartVantage(const std::string& args, const std::string& out_path,
                 const std::string& err_path) {
  const std::string command = absl::StrCat("exec ", VANTAGE_BINARY, " ", args,
                                           " >", out_path, " 2>", err_path);
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

int WaitVantage(int pid, double seconds) {
  for (double waited = 0; waited < seconds; waited += 0.05) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    usleep(50000);
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  return -1;
}

Outcome RunVantage(const std::string& args) {
  const std::string out = TempPath("stdout.txt");
  const std::string err = TempPath("stderr.txt");
  const std::string command =
      absl::StrCat(VANTAGE_BINARY, " ", args, " >", out, " 2>", err);
  const int status = std::system(command.c_str());
  Outcome outcome;
  outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  outcome.out = ReadFile(out);
  outcome.err = ReadFile(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return outcome;
}

}  // namespace vantage
