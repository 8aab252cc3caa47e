#ifndef VANTAGE_LEARNER_ALGORITHMS_A2C_TENSORFLOW_RMSPROP_H_
#define VANTAGE_LEARNER_ALGORITHMS_A2C_TENSORFLOW_RMSPROP_H_

#include <torch/optim/optimizer.h>
#include <torch/optim/rmsprop.h>

#include <vector>

namespace vantage {

// RMSProp as TensorFlow 1's RMSPropOptimizer computes it, which the
// baselines' A2C (and the paper's Atari runs) used:
//   ms <- alpha * ms + (1 - alpha) * g^2,   ms starting at 1,
//   p  <- p - lr * g / sqrt(ms + eps).
// torch::optim::RMSprop differs twice: ms starts at 0, which makes its
// first steps about lr / sqrt(1 - alpha) = 10 lr in every coordinate, and
// eps is added outside the square root, so a coordinate with a tiny
// gradient can still take a step of about lr. Only lr, alpha and eps of the
// options are used (no momentum, centring or weight decay). Its state is
// RMSprop's (step, square_avg), saved and loaded the same way.
class TensorflowRmsprop : public torch::optim::Optimizer {
 public:
  TensorflowRmsprop(std::vector<at::Tensor> parameters,
                    const torch::optim::RMSpropOptions& options);

  at::Tensor step(LossClosure closure = nullptr) override;
  void save(torch::serialize::OutputArchive& archive) const override;
  void load(torch::serialize::InputArchive& archive) override;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_A2C_TENSORFLOW_RMSPROP_H_
