#include "learner/batch/linear_critic.h"

#include <ATen/ATen.h>
#include <torch/serialize/archive.h>

#include <cmath>
#include <sstream>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/parallel/replica_group.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// rllab's features written out for one row.
std::vector<double> RowFeatures(const std::vector<double>& s, int64_t t) {
  std::vector<double> phi;
  for (double v : s) phi.push_back(std::min(10.0, std::max(-10.0, v)));
  for (double v : s) {
    const double c = std::min(10.0, std::max(-10.0, v));
    phi.push_back(c * c);
  }
  const double a = static_cast<double>(t) / 100.0;
  for (double v : {a, a * a, a * a * a, 1.0}) phi.push_back(v);
  return phi;
}

TEST(LinearCriticTest, FeaturesAreClippedObservationsSquaresACubicInTime) {
  const at::Tensor observations =
      at::tensor({0.5f, -12.0f, 3.0f, 40.0f}).reshape({2, 2});
  const at::Tensor steps = at::tensor({0, 250}, at::kLong);
  const at::Tensor phi = LinearCritic::Features(observations, steps);
  ASSERT_EQ(phi.scalar_type(), at::kDouble);
  ASSERT_EQ(phi.sizes(), (at::IntArrayRef{2, 8}));
  const std::vector<std::vector<double>> expected = {
      RowFeatures({0.5, -12.0}, 0), RowFeatures({3.0, 40.0}, 250)};
  for (int64_t r = 0; r < 2; ++r) {
    for (int64_t c = 0; c < 8; ++c) {
      EXPECT_DOUBLE_EQ(phi[r][c].item<double>(), expected[r][c]) << r << c;
    }
  }
}

// Solves A x = b by Gauss-Jordan elimination with partial pivoting.
std::vector<double> Solve(std::vector<std::vector<double>> a,
                          std::vector<double> b) {
  const size_t n = b.size();
  for (size_t col = 0; col < n; ++col) {
    size_t pivot = col;
    for (size_t r = col + 1; r < n; ++r) {
      if (std::fabs(a[r][col]) > std::fabs(a[pivot][col])) pivot = r;
    }
    std::swap(a[col], a[pivot]);
    std::swap(b[col], b[pivot]);
    for (size_t r = 0; r < n; ++r) {
      if (r == col) continue;
      const double f = a[r][col] / a[col][col];
      for (size_t c = col; c < n; ++c) a[r][c] -= f * a[col][c];
      b[r] -= f * b[col];
    }
  }
  for (size_t r = 0; r < n; ++r) b[r] /= a[r][r];
  return b;
}

// The fit against the ridge normal equations built and solved by hand.
TEST(LinearCriticTest, FitsTheRidgeLeastSquaresSolution) {
  at::manual_seed(3);
  const at::Tensor observations = at::randn({300, 3}) * 4;
  const at::Tensor steps = at::randint(0, 500, {300}, at::kLong);
  const at::Tensor targets = at::randn({300}) * 20 - 50;
  LinearCritic critic(3);
  const at::Tensor phi = LinearCritic::Features(observations, steps);
  EXPECT_TRUE(at::equal(critic.Predict(phi), at::zeros({300})));
  absl::StatusOr<double> loss = critic.Fit(phi, targets, *SoloReplicaGroup());
  ASSERT_TRUE(loss.ok()) << loss.status();

  const int64_t width = phi.size(1);
  std::vector<std::vector<double>> xtx(width, std::vector<double>(width));
  std::vector<double> xty(width);
  for (int64_t r = 0; r < 300; ++r) {
    for (int64_t i = 0; i < width; ++i) {
      const double xi = phi[r][i].item<double>();
      xty[i] += xi * targets[r].item<float>();
      for (int64_t j = 0; j < width; ++j) {
        xtx[i][j] += xi * phi[r][j].item<double>();
      }
    }
  }
  for (int64_t i = 0; i < width; ++i) xtx[i][i] += LinearCritic::kRidge;
  const std::vector<double> w = Solve(xtx, xty);
  double squared = 0;
  for (int64_t r = 0; r < 300; ++r) {
    double prediction = 0;
    for (int64_t i = 0; i < width; ++i) {
      prediction += w[i] * phi[r][i].item<double>();
    }
    EXPECT_NEAR(critic.Predict(phi)[r].item<float>(), prediction,
                1e-4 * (1 + std::fabs(prediction)));
    const double error = prediction - targets[r].item<float>();
    squared += error * error;
  }
  for (int64_t i = 0; i < width; ++i) {
    EXPECT_NEAR(critic.coefficients()[i].item<double>(), w[i],
                1e-6 * (1 + std::fabs(w[i])))
        << i;
  }
  EXPECT_NEAR(*loss, squared / 300, 1e-6 * squared / 300);
}

// Returns that are a function of time alone (a constant reward until a
// time limit) are what the cubic in t is for: explained almost exactly.
TEST(LinearCriticTest, ATimeLimitsReturnsAreExplainedByTheStep) {
  const int64_t limit = 200;
  std::vector<float> returns;
  for (int64_t t = 0; t < limit; ++t) {
    returns.push_back(
        static_cast<float>(-(1 - std::pow(0.99, limit - t)) / 0.01));
  }
  const at::Tensor steps = at::arange(limit, at::kLong);
  const at::Tensor phi = LinearCritic::Features(at::zeros({limit, 2}), steps);
  LinearCritic critic(2);
  const at::Tensor targets = at::tensor(returns);
  ASSERT_TRUE(critic.Fit(phi, targets, *SoloReplicaGroup()).ok());
  const double variance = targets.var(false).item<double>();
  const double residual =
      (critic.Predict(phi) - targets).pow(2).mean().item<double>();
  EXPECT_LT(residual, 1e-3 * variance);
}

TEST(LinearCriticTest, ANonFiniteSystemKeepsTheOldWeights) {
  LinearCritic critic(1);
  const at::Tensor phi =
      LinearCritic::Features(at::ones({4, 1}), at::arange(4, at::kLong));
  ASSERT_TRUE(
      critic.Fit(phi, at::arange(4, at::kFloat), *SoloReplicaGroup()).ok());
  const at::Tensor before = critic.coefficients().clone();
  const absl::StatusOr<double> loss =
      critic.Fit(phi, at::tensor({1.0f, NAN, 2.0f, 3.0f}), *SoloReplicaGroup());
  EXPECT_EQ(loss.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(loss.status().message()),
              HasSubstr("its weights are as before"));
  EXPECT_TRUE(at::equal(critic.coefficients(), before));
}

Rollout TwoStepRollout(float first, int64_t first_step) {
  Rollout r;
  r.actor_id = 4;
  r.env_slot = 1;
  r.observations = at::tensor({first, first + 1, first + 2}).reshape({3, 1});
  r.truncated = at::tensor({0, 1}, at::kInt).to(at::kBool);
  r.terminated = at::zeros({2}, at::kBool);
  r.final_observations = at::tensor({50.0f}).reshape({1, 1});
  r.episode_steps =
      at::tensor({first_step, first_step + 1, int64_t{0}}, at::kLong);
  return r;
}

// Values come in CriticValuesOf's order; a truncated step's final
// observation is valued one step after the step, and a rollout that does
// not say where in its episode it is is refused by name.
TEST(LinearCriticTest, ValuesEveryObservationTheEstimatorsNeed) {
  LinearCritic critic(1);
  const std::vector<Rollout> rollouts = {TwoStepRollout(1, 5),
                                         TwoStepRollout(7, 0)};
  const at::Tensor phi = LinearCritic::Features(
      at::tensor({1.0f, 2.0f, 3.0f, 7.0f, 8.0f, 9.0f, 50.0f, 50.0f})
          .reshape({8, 1}),
      at::tensor({5, 6, 0, 0, 1, 0, 7, 2}, at::kLong));
  ASSERT_TRUE(critic.Fit(phi, at::randn({8}), *SoloReplicaGroup()).ok());
  absl::StatusOr<at::Tensor> values = critic.Values(rollouts);
  ASSERT_TRUE(values.ok()) << values.status();
  EXPECT_TRUE(at::equal(*values, critic.Predict(phi)));

  std::vector<Rollout> unsaid = rollouts;
  unsaid[1].episode_steps = at::Tensor();
  EXPECT_THAT(std::string(critic.Values(unsaid).status().message()),
              HasSubstr("the rollout of actor 4 slot 1 does not say which "
                        "step of its episode"));
}

TEST(LinearCriticTest, SavesAndRefusesWeightsThatDoNotFit) {
  LinearCritic critic(2);
  const at::Tensor phi =
      LinearCritic::Features(at::randn({20, 2}), at::arange(20, at::kLong));
  ASSERT_TRUE(critic.Fit(phi, at::randn({20}), *SoloReplicaGroup()).ok());
  torch::serialize::OutputArchive out;
  critic.Save(out);
  std::ostringstream bytes;
  out.save_to(bytes);
  torch::serialize::InputArchive in;
  std::istringstream read(bytes.str());
  in.load_from(read);
  LinearCritic loaded(2);
  ASSERT_TRUE(loaded.Load(in).ok());
  EXPECT_TRUE(at::equal(loaded.coefficients(), critic.coefficients()));

  for (const at::Tensor& bad :
       {at::zeros({7}, at::kDouble), at::zeros({8}, at::kFloat),
        at::full({8}, NAN, at::kDouble)}) {
    const absl::Status status = loaded.Restore(bad);
    EXPECT_THAT(std::string(status.message()),
                HasSubstr("must hold 8 finite doubles"));
    EXPECT_TRUE(at::equal(loaded.coefficients(), critic.coefficients()));
  }
}

}  // namespace
}  // namespace vantage
