// Writes the binary seed corpora of the fuzzers (and the resolved default
// run config, as a run's config.json holds it) under the directory given:
//   make_corpus tests/fuzz/corpus
// The JSON and MJCF seeds are written by hand.

#include <ATen/ATen.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "common/rollout/segment_queue.h"
#include "deploy/run/run_config.h"
#include "learner/checkpoint/checkpoint.h"
#include "proto/vantage.pb.h"
#include "proto/wire_format.h"
#include "tests/fuzz/fuzz_fixtures.h"

namespace vantage {
namespace {

void Check(const absl::Status& status) {
  if (!status.ok()) {
    std::fprintf(stderr, "make_corpus: %s\n", status.ToString().c_str());
    std::exit(1);
  }
}

void WriteFile(const std::filesystem::path& path, const std::string& bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << bytes;
  if (!file)
    Check(absl::InternalError(absl::StrCat("cannot write ", path.string())));
  std::printf("%s (%zu bytes)\n", path.c_str(), bytes.size());
}

std::string Serialized(const Segment& segment) {
  pb::Segment proto;
  SegmentToProto(segment, &proto);
  return proto.SerializeAsString();
}

void WriteSegments(const std::filesystem::path& dir) {
  const EnvSpec box = FuzzContinuousSpec();
  const EnvSpec grid = FuzzDiscreteSpec();
  const Segment continuous = FuzzSegment(box, 5, 0, 3, 1);
  Check(ValidateSegment(continuous, box, kFuzzMaxSteps));
  WriteFile(dir / "continuous_5.bin", Serialized(continuous));
  const Segment discrete = FuzzSegment(grid, 4, 1, 0, 2);
  Check(ValidateSegment(discrete, grid, kFuzzMaxSteps));
  WriteFile(dir / "discrete_4.bin", Serialized(discrete));
  const Segment longest = FuzzSegment(box, kFuzzMaxSteps, 2, 7, 3);
  Check(ValidateSegment(longest, box, kFuzzMaxSteps));
  WriteFile(dir / "continuous_128.bin", Serialized(longest));
  // Refused: a second truncation without its final observation.
  Segment missing = FuzzSegment(box, 6, 0, 4, 4);
  missing.truncated[4] = true;
  missing.episode_returns.push_back(0.5);
  missing.episode_lengths.push_back(2);
  WriteFile(dir / "missing_final_observation.bin", Serialized(missing));
}

void WriteRegistrations(const std::filesystem::path& dir) {
  pb::RegisterRequest request;
  EnvSpecToProto(FuzzContinuousSpec(), request.mutable_spec());
  request.set_actor_name("actor-0");
  request.set_num_envs(2);
  WriteFile(dir / "matching.bin", request.SerializeAsString());
  request.set_num_envs(64);
  WriteFile(dir / "matching_64_envs.bin", request.SerializeAsString());
  pb::RegisterRequest other = request;
  other.mutable_spec()->set_action_high(0, 2.5);
  WriteFile(dir / "other_bounds.bin", other.SerializeAsString());
  other.Clear();
  EnvSpecToProto(FuzzDiscreteSpec(), other.mutable_spec());
  other.set_num_envs(1);
  WriteFile(dir / "discrete.bin", other.SerializeAsString());
}

// A learner after one update (so that the optimiser has state), saved
// with the extras a run's checkpoints carry.
void WriteCheckpoints(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  for (const std::string algorithm : {"ppo", "a2c", "trpo"}) {
    const LearnerConfig config = FuzzLearnerConfig(algorithm);
    absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
        LearnerCore::Create(config);
    Check(learner.status());
    SegmentQueue queue(config.rollouts_per_batch);
    for (int64_t slot = 0; slot < config.rollouts_per_batch; ++slot) {
      Check(queue.Send(
          FuzzSegment(config.spec, config.horizon, slot, 0, 10 + slot)));
    }
    Check((*learner)->RunUpdate(queue).status());
    pb::RunConfig run;
    run.set_mode("local");
    Check(SelectAlgorithm(algorithm, run));
    absl::StatusOr<pb::RunConfig> resolved = ResolveRunConfig(run);
    Check(resolved.status());
    const std::string path = (dir / (algorithm + ".pt")).string();
    Check(WriteCheckpoint(
        path, **learner,
        {{"config", RunConfigToJson(*resolved)}, {"elapsed_seconds", "1.5"}}));
    Check(ReadCheckpoint(path, config).status());
    std::printf("%s (%ju bytes)\n", path.c_str(),
                static_cast<uintmax_t>(std::filesystem::file_size(path)));
  }
}

void WriteRunConfigs(const std::filesystem::path& dir) {
  absl::StatusOr<pb::RunConfig> resolved = ResolveRunConfig(pb::RunConfig());
  Check(resolved.status());
  WriteFile(dir / "resolved_default.json", RunConfigToJson(*resolved));
}

}  // namespace
}  // namespace vantage

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_corpus CORPUS_DIR\n");
    return 2;
  }
  at::set_num_threads(1);
  const std::filesystem::path root = argv[1];
  vantage::WriteSegments(root / "segment");
  vantage::WriteRegistrations(root / "register");
  vantage::WriteCheckpoints(root / "checkpoint");
  vantage::WriteRunConfigs(root / "run_config");
  return 0;
}
