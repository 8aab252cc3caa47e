#ifndef VANTAGE_ACTOR_POLICY_EVALUATOR_H_
#define VANTAGE_ACTOR_POLICY_EVALUATOR_H_

// Evaluation during training: a policy version acting deterministically
// (the Gaussian's mean, the most likely action) on episodes of its own.
// Every evaluation of a run plays the same episodes (the same reset seeds,
// from a generator salted apart from training's environments), so versions
// are compared on equal terms and no evaluation touches training's
// episodes or random streams.

#include <cstdint>
#include <memory>

#include "absl/status/statusor.h"
#include "actor/actor_config.h"
#include "common/env/environment.h"
#include "common/rollout/policy_evaluation.h"

namespace vantage {

class PolicyRunner;
struct PolicyWeights;

class PolicyEvaluator {
 public:
  // An episode of an environment without a time limit ends here.
  static constexpr int64_t kMaxEpisodeSteps = 100000;

  // One environment of `actor`'s env and wrapping (its network and
  // observation clip too); its episode seeds come from `actor.seed`.
  static absl::StatusOr<std::unique_ptr<PolicyEvaluator>> Create(
      const ActorConfig& actor, int episodes);
  ~PolicyEvaluator();

  const EnvSpec& spec() const;
  // The version's returns and lengths over the evaluator's episodes, in
  // order. Weights that do not fit the run's network, or an environment
  // error, are returned as errors.
  absl::StatusOr<PolicyEvaluation> Evaluate(const PolicyWeights& weights);

 private:
  PolicyEvaluator(std::unique_ptr<Environment> env,
                  std::unique_ptr<PolicyRunner> runner, int episodes,
                  uint64_t seed);
  absl::Status PlayEpisode(uint64_t seed, double& total, int64_t& length);

  struct FastPolicy;

  std::unique_ptr<Environment> env_;
  std::unique_ptr<PolicyRunner> runner_;
  std::unique_ptr<FastPolicy> fast_;
  const int episodes_;
  const uint64_t seed_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_POLICY_EVALUATOR_H_
