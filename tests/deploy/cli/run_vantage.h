#ifndef VANTAGE_TESTS_DEPLOY_CLI_RUN_VANTAGE_H_
#define VANTAGE_TESTS_DEPLOY_CLI_RUN_VANTAGE_H_

// Runs the real `vantage` binary (path compiled in as VANTAGE_BINARY), as a
// user would.

#include <string>

namespace vantage {

struct Outcome {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// `vantage <args>` through the shell; stdout and stderr captured.
Outcome RunVantage(const std::string& args);

// `vantage <args>` in the background, output to the given files; returns
// its process id.
int StartVantage(const std::string& args, const std::string& out_path,
                 const std::string& err_path);
// Waits up to `seconds` for the process to exit and returns its exit code
// (-1 if it was killed by a signal or did not exit in time, then it is
// killed).
int WaitVantage(int pid, double seconds);

std::string ReadFile(const std::string& path);

// ctest runs tests as parallel processes: every path gets the running
// test's name, the process id and a counter so that none share one.
std::string TempPath(const std::string& name);
// TempPath(name), emptied.
std::string FreshDirectory(const std::string& name);
std::string WriteTemp(const std::string& name, const std::string& text);

}  // namespace vantage

#endif  // VANTAGE_TESTS_DEPLOY_CLI_RUN_VANTAGE_H_
