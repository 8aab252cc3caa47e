#include "deploy/observe/scrape_targets.h"

#include <unistd.h>

#include <cstdio>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"

namespace vantage {

std::string ScrapeTargetsJson(const std::vector<ScrapeTarget>& targets) {
  google::protobuf::ListValue list;
  for (const ScrapeTarget& target : targets) {
    google::protobuf::Struct& group =
        *list.add_values()->mutable_struct_value();
    auto& fields = *group.mutable_fields();
    fields["targets"].mutable_list_value()->add_values()->set_string_value(
        target.address);
    auto& labels = *fields["labels"].mutable_struct_value()->mutable_fields();
    for (const auto& [name, value] : target.labels) {
      labels[name].set_string_value(value);
    }
  }
  std::string json;
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  // A ListValue prints as a JSON array; nothing in it can fail to print.
  (void)google::protobuf::util::MessageToJsonString(list, &json, options);
  return json;
}

absl::Status WriteScrapeTargets(const std::string& path,
                                const std::vector<ScrapeTarget>& targets) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::trunc);
    file << ScrapeTargetsJson(targets);
    if (!file.flush()) {
      return absl::InternalError(absl::StrCat("cannot write ", temporary));
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    return absl::InternalError(absl::StrCat("cannot write ", path));
  }
  return absl::OkStatus();
}

std::string ScrapeAddress(const std::string& host, int port) {
  if (host.empty() || host == "0.0.0.0" || host == "[::]") {
    char name[256] = {};
    return absl::StrCat(
        gethostname(name, sizeof(name) - 1) == 0 ? name : "localhost", ":",
        port);
  }
  return absl::StrCat(host, ":", port);
}

}  // namespace vantage
