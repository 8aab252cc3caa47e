#ifndef VANTAGE_ACTOR_ACTOR_CORE_H_
#define VANTAGE_ACTOR_ACTOR_CORE_H_

#include <ATen/core/Generator.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "actor/actor_config.h"
#include "actor/vector_env.h"
#include "common/nn/mlp_policy_kernel.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "common/rollout/segment_queue.h"

namespace vantage {

// Runs the policy only: vectorised environments, batched inference with the
// latest weights (the learner recomputes values itself), segments out.
class ActorCore {
 public:
  static absl::StatusOr<std::unique_ptr<ActorCore>> Create(
      const ActorConfig& config);

  const EnvSpec& spec() const { return envs_->spec(); }
  int64_t policy_version() const { return version_; }
  // The seed its environments were created with.
  uint64_t env_seed() const { return config_.seed; }
  // The id segments carry. A learner assigns one per registration, so an
  // actor that registers again (after the learner restarted) starts new
  // streams that are never stitched onto the old ones.
  void set_stream_actor_id(int64_t id) { stream_actor_id_ = id; }
  int64_t env_steps() const { return env_steps_; }
  // Wall-clock seconds spent so far in batched inference and in stepping
  // the environments (for the actor's metrics).
  double inference_seconds() const { return inference_seconds_; }
  double env_seconds() const { return env_seconds_; }

  // Takes effect from the next segment on. An MLP policy then acts through
  // MlpPolicyKernel (a copy of these weights); any other on LibTorch, which
  // the first SetWeights says on stderr.
  absl::Status SetWeights(const PolicyWeights& weights);
  // Whether the current weights act through MlpPolicyKernel.
  bool acts_without_libtorch() const { return kernel_.has_value(); }

  // Steps every environment segment_length times and sends one segment per
  // environment slot to `sink`. Acting needs weights from the learner
  // first (FailedPrecondition otherwise), so every action comes from a
  // published, reproducible policy version.
  absl::Status CollectSegments(SegmentSink& sink);

  // Everything but the weights that decides the next segments: the
  // environments (VectorEnv::SaveState), the action-sampling generator,
  // env_steps(), each slot's next sequence number and a recurrent policy's
  // state in each slot, so that an actor
  // restored from it continues bit for bit. The policy weights, normaliser
  // and policy_version() are not in it: after RestoreState the learner
  // sends its weights again with SetWeights (acting still needs them).
  // Call between CollectSegments calls.
  absl::StatusOr<std::string> SaveState() const;
  // Needs a state saved by an actor with the same env, num_envs and
  // actor_id. All or nothing: on any error (InvalidArgument for a bad blob)
  // the actor is left as it was.
  absl::Status RestoreState(absl::string_view state);

 private:
  ActorCore(const ActorConfig& config, std::unique_ptr<VectorEnv> envs);
  // The policy's actions [m, act] and their log-probabilities [m] for the
  // environments' current observations (observations_row, as segments
  // keep them, for LibTorch), into actions_ too.
  void Act(const at::Tensor& observations_row, float* actions,
           float* log_probs);
  // CollectSegments' buffers, defined in the .cc: only its steps use them.
  struct Rollout;
  // Acts and steps every environment once, timing both, and records step t.
  absl::Status CollectStep(int64_t t, Rollout& rollout);
  // Step t's rewards, episode ends and finished episodes, and the next
  // observations.
  void RecordStep(int64_t t, Rollout& rollout);
  // One segment per slot, numbered in the slot's sequence.
  absl::Status SendSegments(Rollout& rollout, SegmentSink& sink);

  const ActorConfig config_;
  std::unique_ptr<VectorEnv> envs_;
  PolicyNetwork policy_;
  RunningMeanStd normalizer_;
  std::optional<MlpPolicyKernel> kernel_;
  std::vector<float> kernel_outputs_;
  bool told_libtorch_ = false;
  at::Generator generator_;
  int64_t version_ = 0;
  int64_t stream_actor_id_;
  double inference_seconds_ = 0.0;
  double env_seconds_ = 0.0;
  bool has_weights_ = false;
  int64_t env_steps_ = 0;
  std::vector<int64_t> next_sequence_;
  std::vector<double> actions_;
  // A recurrent policy's state per slot [num_envs, state size], zero where
  // an episode starts; empty for a feed-forward policy.
  std::vector<float> core_states_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ACTOR_CORE_H_
