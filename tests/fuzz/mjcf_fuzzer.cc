// The <custom> block of a `mjcf:PATH` environment (MakeMjcfEnv), which
// turns a MuJoCo model's numeric and text entries into the task: the input
// is the block's contents around a fixed sliding box with two motors,
// written to a file and loaded (MuJoCo errors become statuses through
// GuardMujoco's mju_user_error handler). An environment that is made must
// have a spec the wire format accepts and must reset and step; only models
// of at most kMaxFrameSkip physics steps per step are stepped.
//
// Inputs that close the block are skipped: MuJoCo's XML parser is not
// what this fuzzer is for.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "actor/envs/mujoco/gym_tasks.h"
#include "proto/wire_format.h"
#include "tests/fakes/box_model.h"
#include "tests/fuzz/fuzz_fixtures.h"

namespace vantage {
namespace {

constexpr double kTimestep = 0.01;
constexpr int kMaxFrameSkip = 64;

void CheckEnvironment(Environment& env) {
  const EnvSpec& spec = env.spec();
  pb::EnvSpec proto;
  EnvSpecToProto(spec, &proto);
  // Only the rules every learner applies, not a learner's size limits.
  SpecLimits limits;
  limits.max_episode_steps = INT64_MAX;
  if (absl::StatusOr<EnvSpec> decoded = EnvSpecFromProto(proto, limits);
      !decoded.ok()) {
    FuzzFail("an MJCF environment's spec is refused", decoded.status());
  }
  if (spec.control_dt > kMaxFrameSkip * kTimestep) return;
  std::vector<double> observation(spec.observation_size);
  if (absl::Status status = env.Reset(1, absl::MakeSpan(observation));
      !status.ok()) {
    FuzzFail("an MJCF environment does not reset", status);
  }
  const std::vector<double> action(spec.action_size, 0.5);
  for (int t = 0; t < 3; ++t) {
    absl::StatusOr<StepResult> step =
        env.Step(action, absl::MakeSpan(observation));
    if (!step.ok())
      FuzzFail("an MJCF environment does not step", step.status());
    if (step->terminated || step->truncated) break;
  }
}

}  // namespace
}  // namespace vantage

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  const std::string custom(reinterpret_cast<const char*>(data), size);
  if (absl::StrContains(custom, "</custom") ||
      custom.find('\0') != custom.npos) {
    return 0;
  }
  static const std::string path = FuzzTempPath("mjcf_fuzzer.xml");
  {
    std::ofstream file(path, std::ios::trunc);
    file << BoxModel(custom);
    if (!file) return 0;
  }
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeMjcfEnv(path);
  if (env.ok()) CheckEnvironment(**env);
  std::remove(path.c_str());
  return 0;
}
