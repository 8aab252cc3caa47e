// Run-config JSON as `vantage train --config` and a resumed run read it:
// ParseRunConfigJson, then ResolveRunConfig. A resolved config must resolve
// to itself again (a run's config.json is resolved once more on resume) and
// survive RunConfigToJson -> ParseRunConfigJson unchanged.

#include <google/protobuf/util/message_differencer.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "deploy/run/run_config.h"
#include "tests/fuzz/fuzz_fixtures.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  using google::protobuf::util::MessageDifferencer;
  const std::string json(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<pb::RunConfig> parsed = ParseRunConfigJson(json);
  if (!parsed.ok()) return 0;
  absl::StatusOr<pb::RunConfig> resolved = ResolveRunConfig(*parsed);
  if (!resolved.ok()) return 0;
  absl::StatusOr<pb::RunConfig> again = ResolveRunConfig(*resolved);
  if (!again.ok())
    FuzzFail("a resolved config does not resolve", again.status());
  if (!MessageDifferencer::Equals(*again, *resolved)) {
    FuzzFail("resolving a resolved config changed it",
             absl::InternalError(again->ShortDebugString()));
  }
  absl::StatusOr<pb::RunConfig> reread =
      ParseRunConfigJson(RunConfigToJson(*resolved));
  if (!reread.ok())
    FuzzFail("a resolved config's JSON does not parse", reread.status());
  if (!MessageDifferencer::Equals(*reread, *resolved)) {
    FuzzFail("a resolved config changed through its JSON",
             absl::InternalError(reread->ShortDebugString()));
  }
  return 0;
}
