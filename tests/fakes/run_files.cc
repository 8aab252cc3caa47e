#include "tests/fakes/run_files.h"

#include <fstream>

#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"

namespace vantage {

std::vector<std::string> DeterministicProgress(const std::string& run_dir) {
  std::ifstream file(run_dir + "/progress.csv");
  std::vector<std::string> rows;
  std::string line;
  while (std::getline(file, line)) {
    std::vector<std::string> fields = absl::StrSplit(line, ',');
    fields.resize(fields.size() < 2 ? 0 : fields.size() - 2);
    rows.push_back(absl::StrJoin(fields, ","));
  }
  return rows;
}

}  // namespace vantage
