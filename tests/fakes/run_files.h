#ifndef VANTAGE_TESTS_FAKES_RUN_FILES_H_
#define VANTAGE_TESTS_FAKES_RUN_FILES_H_

// Reading a run directory the way the training tests compare runs.

#include <string>
#include <vector>

namespace vantage {

// progress.csv's lines without the wall-clock columns (the last two), the
// header first; empty if there is no file.
std::vector<std::string> DeterministicProgress(const std::string& run_dir);

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_RUN_FILES_H_
