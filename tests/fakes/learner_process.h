#ifndef VANTAGE_TESTS_FAKES_LEARNER_PROCESS_H_
#define VANTAGE_TESTS_FAKES_LEARNER_PROCESS_H_

// A real `vantage learner` process on a loopback port, for the tests that
// run the learner and actors as separate processes.

#include <cstdint>
#include <string>
#include <vector>

namespace vantage {

struct Learner {
  int pid = 0;
  std::string port;
  std::string out, err;
};

// Starts `vantage learner <args>` and waits for its port file.
Learner StartLearner(const std::string& args);

// A field of /proc/PID/status: in bytes for sizes ("VmRSS"), as a count
// otherwise ("Threads"); -1 if absent.
int64_t ProcessStatusField(int pid, const std::string& field);

// The children of `parent` whose command line contains `word`.
std::vector<int> ChildrenRunning(int parent, const std::string& word);

// The port a process printed on stderr as "<who>: metrics on port N",
// waiting up to 30 s; 0 if it never did.
int MetricsPort(const std::string& err_path, const std::string& who);

// The value of a sample (with its labels, if any, as printed) in
// Prometheus text; -1 if absent.
double Sample(const std::string& text, const std::string& name);

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_LEARNER_PROCESS_H_
