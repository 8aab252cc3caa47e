#include "common/util/cpu_model.h"

#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"

namespace vantage {
namespace {

// The value of the first "key : value" line with this key, or "".
std::string Field(const std::string& cpuinfo, absl::string_view key) {
  for (absl::string_view line : absl::StrSplit(cpuinfo, '\n')) {
    const std::vector<absl::string_view> parts =
        absl::StrSplit(line, absl::MaxSplits(':', 1));
    if (parts.size() == 2 && absl::StripAsciiWhitespace(parts[0]) == key) {
      return std::string(absl::StripAsciiWhitespace(parts[1]));
    }
  }
  return "";
}

}  // namespace

std::string CpuModelFromCpuinfo(const std::string& cpuinfo) {
  std::string model = Field(cpuinfo, "model name");
  if (model.empty()) {
    const std::string implementer = Field(cpuinfo, "CPU implementer");
    const std::string part = Field(cpuinfo, "CPU part");
    if (!implementer.empty()) {
      model = absl::StrCat("implementer ", implementer, " part ", part);
    }
  }
  // Kept to what a JSON string and a CSV field hold without escapes.
  std::string clean;
  for (char c : model) {
    if (c != '"' && c != '\\' && c != ',' &&
        static_cast<unsigned char>(c) >= 32) {
      clean.push_back(c);
    }
  }
  return clean.empty() ? "unknown" : clean;
}

std::string CpuModel() {
  std::ifstream file("/proc/cpuinfo");
  std::stringstream text;
  text << file.rdbuf();
  return CpuModelFromCpuinfo(text.str());
}

}  // namespace vantage
