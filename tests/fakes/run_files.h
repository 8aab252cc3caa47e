#ifndef VANTAGE_TESTS_FAKES_RUN_FILES_H_
#define VANTAGE_TESTS_FAKES_RUN_FILES_H_

// Reading a run directory the way the training tests compare runs.

#include <cstddef>
#include <string>
#include <vector>

namespace vantage {

// progress.csv's lines without the wall-clock columns (the last two), the
// header first; empty if there is no file.
std::vector<std::string> DeterministicProgress(const std::string& run_dir);

// The field of `column` in `rows[row]`, where rows[0] is the header (as
// DeterministicProgress gives them); "<no column NAME>" if the header or
// the row lacks it, so that a test comparing it fails saying why.
std::string ProgressField(const std::vector<std::string>& rows, size_t row,
                          const std::string& column);

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_RUN_FILES_H_
