#include "tests/fakes/run_files.h"

#include <algorithm>
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

std::string ProgressField(const std::vector<std::string>& rows, size_t row,
                          const std::string& column) {
  const std::string missing = "<no column " + column + ">";
  if (rows.empty() || row >= rows.size()) return missing;
  const std::vector<std::string> names = absl::StrSplit(rows[0], ',');
  const std::vector<std::string> fields = absl::StrSplit(rows[row], ',');
  const auto at = std::find(names.begin(), names.end(), column);
  const auto index = static_cast<size_t>(at - names.begin());
  return at == names.end() || index >= fields.size() ? missing : fields[index];
}

}  // namespace vantage
