#include "common/advantage/advantage.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// ---------------------------------------------------------------------------
// Brute-force reference, written straight from DESIGN.md section 3 with
// plain loops over one stream at a time.

struct Rollout {
  int64_t steps = 0;
  int64_t streams = 0;
  // [t][s]
  std::vector<std::vector<double>> rewards, values, truncation_values;
  std::vector<std::vector<bool>> terminated, truncated;
  std::vector<double> last_values;  // [s]
};

// The value after step u that ends the walk there.
double Bootstrap(const Rollout& r, int64_t u, int64_t s) {
  if (r.terminated[u][s]) return 0.0;
  if (r.truncated[u][s]) return r.truncation_values[u][s];
  if (u + 1 == r.steps) return r.last_values[s];
  return r.values[u + 1][s];
}

bool EndsAt(const Rollout& r, int64_t u, int64_t s) {
  return r.terminated[u][s] || r.truncated[u][s] || u + 1 == r.steps;
}

double ReferenceKStep(const Rollout& r, int64_t t, int64_t s, int64_t k,
                      double gamma) {
  double sum = 0.0;
  double discount = 1.0;
  for (int64_t n = 1, u = t;; ++n, ++u) {
    sum += discount * r.rewards[u][s];
    discount *= gamma;
    if (n == k || EndsAt(r, u, s)) {
      return sum + discount * Bootstrap(r, u, s) - r.values[t][s];
    }
  }
}

double ReferenceGae(const Rollout& r, int64_t t, int64_t s, double gamma,
                    double lambda) {
  double sum = 0.0;
  double weight = 1.0;
  for (int64_t u = t;; ++u) {
    const double delta =
        r.rewards[u][s] + gamma * Bootstrap(r, u, s) - r.values[u][s];
    sum += weight * delta;
    if (EndsAt(r, u, s)) return sum;
    weight *= gamma * lambda;
  }
}

double ReferenceStatistic(std::vector<double> members,  // in ascending k
                          const Statistic& statistic) {
  switch (statistic.kind) {
    case StatisticKind::kMax:
      return *std::max_element(members.begin(), members.end());
    case StatisticKind::kMin:
      return *std::min_element(members.begin(), members.end());
    case StatisticKind::kMaxAbs: {
      double best = members[0];
      for (double a : members) {
        if (std::fabs(a) > std::fabs(best)) best = a;
      }
      return best;
    }
    case StatisticKind::kOrder:
      std::sort(members.begin(), members.end());
      return members[statistic.order - 1];
    case StatisticKind::kGae:
      break;
  }
  ADD_FAILURE() << "no reference for gae";
  return 0.0;
}

// ---------------------------------------------------------------------------

Rollout RandomRollout(int64_t steps, int64_t streams, double p_terminate,
                      double p_truncate, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::bernoulli_distribution terminate(p_terminate), truncate(p_truncate);
  Rollout r;
  r.steps = steps;
  r.streams = streams;
  r.rewards.assign(steps, std::vector<double>(streams));
  r.values = r.truncation_values = r.rewards;
  r.terminated.assign(steps, std::vector<bool>(streams));
  r.truncated = r.terminated;
  for (int64_t t = 0; t < steps; ++t) {
    for (int64_t s = 0; s < streams; ++s) {
      r.rewards[t][s] = normal(rng);
      r.values[t][s] = 3.0 * normal(rng);
      r.terminated[t][s] = terminate(rng);
      r.truncated[t][s] = truncate(rng);
      // Entries at untruncated steps must be ignored: make them poison.
      r.truncation_values[t][s] = r.truncated[t][s] ? normal(rng) : 1e300;
    }
  }
  for (int64_t s = 0; s < streams; ++s) r.last_values.push_back(normal(rng));
  return r;
}

AdvantageInputs ToInputs(const Rollout& r, at::ScalarType dtype = at::kDouble) {
  AdvantageInputs in;
  in.rewards = at::empty({r.steps, r.streams}, at::kDouble);
  in.values = at::empty({r.steps, r.streams}, at::kDouble);
  in.truncation_values = at::empty({r.steps, r.streams}, at::kDouble);
  in.terminated = at::empty({r.steps, r.streams}, at::kBool);
  in.truncated = at::empty({r.steps, r.streams}, at::kBool);
  for (int64_t t = 0; t < r.steps; ++t) {
    for (int64_t s = 0; s < r.streams; ++s) {
      in.rewards[t][s] = r.rewards[t][s];
      in.values[t][s] = r.values[t][s];
      in.truncation_values[t][s] = r.truncation_values[t][s];
      in.terminated[t][s] = static_cast<bool>(r.terminated[t][s]);
      in.truncated[t][s] = static_cast<bool>(r.truncated[t][s]);
    }
  }
  in.last_values = at::empty({r.streams}, at::kDouble);
  for (int64_t s = 0; s < r.streams; ++s) in.last_values[s] = r.last_values[s];
  in.rewards = in.rewards.to(dtype);
  in.values = in.values.to(dtype);
  in.last_values = in.last_values.to(dtype);
  // Stays double: the float32 cast of the 1e300 poison would be inf.
  return in;
}

void ExpectClose(double actual, double expected, const std::string& where) {
  ASSERT_NEAR(actual, expected, 1e-9 * (1.0 + std::fabs(expected))) << where;
}

struct Case {
  int64_t steps;
  int64_t streams;
  double p_terminate;
  double p_truncate;
};

std::vector<Case> Cases() {
  return {{1, 1, 0.0, 0.0},    {1, 4, 0.5, 0.5},    {7, 2, 0.0, 0.0},
          {37, 3, 0.1, 0.05},  {64, 5, 0.3, 0.3},   {200, 4, 0.02, 0.01},
          {300, 2, 0.0, 0.02}, {129, 16, 0.05, 0.0}};
}

std::vector<std::vector<int64_t>> Ensembles() {
  std::vector<int64_t> powers;
  for (int i = 0; i < 12; ++i) powers.push_back(int64_t{1} << i);
  return {{1}, {1, 16, 64, 2048}, {3, 1, 5000}, {2}, powers, {250, 7, 40}};
}

TEST(AdvantageReferenceTest, KStepEstimatesMatchBruteForce) {
  const double gamma = 0.97;
  uint64_t seed = 1;
  for (const Case& c : Cases()) {
    const Rollout r =
        RandomRollout(c.steps, c.streams, c.p_terminate, c.p_truncate, seed++);
    for (const auto& ks : Ensembles()) {
      const absl::StatusOr<at::Tensor> estimates =
          ComputeKStepEstimates(ToInputs(r), gamma, ks);
      ASSERT_TRUE(estimates.ok()) << estimates.status();
      for (size_t m = 0; m < ks.size(); ++m) {
        for (int64_t t = 0; t < r.steps; ++t) {
          for (int64_t s = 0; s < r.streams; ++s) {
            ExpectClose((*estimates)[m][t][s].item<double>(),
                        ReferenceKStep(r, t, s, ks[m], gamma),
                        "k=" + std::to_string(ks[m]) +
                            " t=" + std::to_string(t) +
                            " T=" + std::to_string(r.steps));
          }
        }
      }
    }
  }
}

TEST(AdvantageReferenceTest, GaeMatchesBruteForce) {
  uint64_t seed = 100;
  for (const Case& c : Cases()) {
    const Rollout r =
        RandomRollout(c.steps, c.streams, c.p_terminate, c.p_truncate, seed++);
    for (const auto& [gamma, lambda] :
         {std::make_pair(0.99, 0.95), std::make_pair(1.0, 1.0),
          std::make_pair(0.5, 0.0), std::make_pair(0.9, 0.7)}) {
      const absl::StatusOr<at::Tensor> gae =
          ComputeGae(ToInputs(r), gamma, lambda);
      ASSERT_TRUE(gae.ok()) << gae.status();
      for (int64_t t = 0; t < r.steps; ++t) {
        for (int64_t s = 0; s < r.streams; ++s) {
          ExpectClose((*gae)[t][s].item<double>(),
                      ReferenceGae(r, t, s, gamma, lambda),
                      "t=" + std::to_string(t));
        }
      }
    }
  }
}

TEST(AdvantageReferenceTest, EveryStatisticMatchesBruteForce) {
  const double gamma = 0.95;
  uint64_t seed = 200;
  for (const Case& c : Cases()) {
    const Rollout r =
        RandomRollout(c.steps, c.streams, c.p_terminate, c.p_truncate, seed++);
    for (const auto& ks : Ensembles()) {
      std::vector<int64_t> sorted = ks;
      std::sort(sorted.begin(), sorted.end());
      std::vector<Statistic> statistics = {{StatisticKind::kMax, 0},
                                           {StatisticKind::kMin, 0},
                                           {StatisticKind::kMaxAbs, 0}};
      for (int d = 1; d <= static_cast<int>(ks.size()); ++d) {
        statistics.push_back({StatisticKind::kOrder, d});
      }
      for (const Statistic& statistic : statistics) {
        AdvantageConfig config;
        config.gamma = gamma;
        config.ensemble = ks;
        config.statistic = statistic;
        const absl::StatusOr<at::Tensor> biased =
            ComputeBiasedAdvantage(ToInputs(r), config);
        ASSERT_TRUE(biased.ok()) << biased.status();
        for (int64_t t = 0; t < r.steps; ++t) {
          for (int64_t s = 0; s < r.streams; ++s) {
            std::vector<double> members;
            for (int64_t k : sorted) {
              members.push_back(ReferenceKStep(r, t, s, k, gamma));
            }
            ExpectClose((*biased)[t][s].item<double>(),
                        ReferenceStatistic(members, statistic),
                        StatisticName(statistic) + " t=" + std::to_string(t));
          }
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Properties.

class AdvantagePropertyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rollout_ = RandomRollout(500, 6, 0.01, 0.005, 7);
    inputs_ = ToInputs(rollout_);
  }

  at::Tensor Biased(const std::string& statistic,
                    std::vector<int64_t> ensemble = {1, 16, 64, 2048}) {
    AdvantageConfig config;
    config.ensemble = ensemble;
    config.statistic = *ParseStatistic(statistic);
    absl::StatusOr<at::Tensor> biased = ComputeBiasedAdvantage(inputs_, config);
    EXPECT_TRUE(biased.ok()) << biased.status();
    return *biased;
  }

  Rollout rollout_;
  AdvantageInputs inputs_;
};

TEST_F(AdvantagePropertyTest, OrderStatisticsLieBetweenMinAndMax) {
  const at::Tensor lo = Biased("min");
  const at::Tensor hi = Biased("max");
  for (int d = 1; d <= 4; ++d) {
    const at::Tensor order = Biased("order:" + std::to_string(d));
    EXPECT_TRUE(at::all(lo <= order).item<bool>()) << d;
    EXPECT_TRUE(at::all(order <= hi).item<bool>()) << d;
  }
  EXPECT_TRUE(at::equal(Biased("order:1"), lo));
  EXPECT_TRUE(at::equal(Biased("order:4"), hi));
}

TEST_F(AdvantagePropertyTest, MaxAbsIsAnEnsembleMember) {
  const std::vector<int64_t> ks = {1, 16, 64, 2048};
  const at::Tensor maxabs = Biased("maxabs", ks);
  const at::Tensor members = *ComputeKStepEstimates(inputs_, 0.99, ks);
  const at::Tensor is_member = (members == maxabs.unsqueeze(0)).any(0);
  EXPECT_TRUE(is_member.all().item<bool>());
  const at::Tensor largest = members.abs().amax(0);
  EXPECT_TRUE(at::equal(maxabs.abs(), largest));
}

TEST_F(AdvantagePropertyTest, MaxAbsTiesGoToTheSmallerK) {
  // A^(1) = +2 and A^(2) = -2 at t = 0: equal magnitude, smaller k wins.
  AdvantageInputs in;
  in.rewards = at::tensor({2.0, -4.0 / 0.5}, at::kDouble).reshape({2, 1});
  in.values = at::zeros({2, 1}, at::kDouble);
  in.terminated = at::zeros({2, 1}, at::kBool);
  in.terminated[1][0] = true;
  in.truncated = at::zeros({2, 1}, at::kBool);
  in.truncation_values = at::zeros({2, 1}, at::kDouble);
  in.last_values = at::zeros({1}, at::kDouble);
  // gamma 0.5: A^(1)_0 = 2 + 0.5 * V_1 = 2, A^(2)_0 = 2 + 0.5 * -8 = -2.
  AdvantageConfig config;
  config.gamma = 0.5;
  config.ensemble = {2, 1};
  config.statistic = *ParseStatistic("maxabs");
  const at::Tensor biased = *ComputeBiasedAdvantage(in, config);
  EXPECT_EQ(biased[0][0].item<double>(), 2.0);
}

TEST_F(AdvantagePropertyTest, SingleMemberMaxIsTheKStepEstimate) {
  for (int64_t k : {1, 5, 64, 100000}) {
    const at::Tensor kstep = *ComputeKStepEstimates(inputs_, 0.99, {k});
    EXPECT_TRUE(at::equal(Biased("max", {k}), kstep[0])) << k;
    EXPECT_TRUE(at::equal(Biased("min", {k}), kstep[0])) << k;
    EXPECT_TRUE(at::equal(Biased("maxabs", {k}), kstep[0])) << k;
    EXPECT_TRUE(at::equal(Biased("order:1", {k}), kstep[0])) << k;
  }
}

TEST_F(AdvantagePropertyTest, LambdaZeroIsOneStepAndLambdaOneIsLongest) {
  const at::Tensor one_step = *ComputeKStepEstimates(inputs_, 0.99, {1});
  const at::Tensor longest = *ComputeKStepEstimates(inputs_, 0.99, {500});
  EXPECT_TRUE(
      at::allclose(*ComputeGae(inputs_, 0.99, 0.0), one_step[0], 1e-12, 1e-12));
  EXPECT_TRUE(
      at::allclose(*ComputeGae(inputs_, 0.99, 1.0), longest[0], 1e-9, 1e-9));
}

TEST_F(AdvantagePropertyTest, RhoZeroIsGaeBitForBitAndRhoOneIsBiased) {
  for (at::ScalarType dtype : {at::kDouble, at::kFloat}) {
    const AdvantageInputs in = ToInputs(rollout_, dtype);
    AdvantageConfig config;
    config.statistic = *ParseStatistic("max");
    config.rho = 0.0;
    std::mt19937_64 rng(1);
    const Advantages zero = *ComputeAdvantages(in, config, rng);
    EXPECT_FALSE(zero.mask.any().item<bool>());
    EXPECT_TRUE(at::equal(zero.mixed, zero.gae));
    EXPECT_TRUE(
        at::equal(zero.gae, *ComputeGae(in, config.gamma, config.lambda)));
    config.rho = 1.0;
    const Advantages one = *ComputeAdvantages(in, config, rng);
    EXPECT_TRUE(one.mask.all().item<bool>());
    EXPECT_TRUE(at::equal(one.mixed, one.biased));
    EXPECT_TRUE(at::equal(one.biased, *ComputeBiasedAdvantage(in, config)));
    EXPECT_FALSE(at::equal(one.biased, one.gae));
  }
}

TEST_F(AdvantagePropertyTest, CriticTargetsAreAlwaysValuePlusGae) {
  for (const char* statistic : {"gae", "max", "min", "maxabs", "order:2"}) {
    AdvantageConfig config;
    config.statistic = *ParseStatistic(statistic);
    config.rho = 1.0;
    std::mt19937_64 rng(3);
    const Advantages out = *ComputeAdvantages(inputs_, config, rng);
    const at::Tensor gae = *ComputeGae(inputs_, config.gamma, config.lambda);
    EXPECT_TRUE(at::equal(out.returns, inputs_.values + gae)) << statistic;
  }
}

// With the gae statistic no sample is biased (progress.csv's
// biased_fraction says 0), and the generator moves exactly as with a
// statistic, so that later draws (minibatches) are those of older runs.
TEST_F(AdvantagePropertyTest, GaeBiasesNoSampleButDrawsItsMask) {
  AdvantageConfig config;
  config.statistic = *ParseStatistic("gae");
  config.rho = 0.4;
  std::mt19937_64 rng(11);
  const Advantages out = *ComputeAdvantages(inputs_, config, rng);
  EXPECT_FALSE(out.mask.any().item<bool>());
  EXPECT_TRUE(at::equal(out.mixed, out.gae));
  config.statistic = *ParseStatistic("maxabs");
  std::mt19937_64 biased_rng(11);
  ASSERT_TRUE(ComputeAdvantages(inputs_, config, biased_rng).ok());
  EXPECT_EQ(rng(), biased_rng());
}

TEST_F(AdvantagePropertyTest, MixedPicksPerSampleByTheMask) {
  AdvantageConfig config;
  config.statistic = *ParseStatistic("maxabs");
  config.rho = 0.4;
  std::mt19937_64 rng(11);
  const Advantages out = *ComputeAdvantages(inputs_, config, rng);
  EXPECT_TRUE(at::equal(out.mixed.masked_select(out.mask),
                        out.biased.masked_select(out.mask)));
  EXPECT_TRUE(at::equal(out.mixed.masked_select(out.mask.logical_not()),
                        out.gae.masked_select(out.mask.logical_not())));
}

TEST(DrawBiasMaskTest, MeanIsNearRho) {
  for (double rho : {0.1, 0.3, 0.5, 0.9}) {
    std::mt19937_64 rng(42);
    const at::Tensor mask = DrawBiasMask({2000, 100}, rho, rng);
    const double mean = mask.to(at::kDouble).mean().item<double>();
    // Standard error is sqrt(rho(1-rho)/2e5) <= 0.0012; 0.006 is 5 of them.
    EXPECT_NEAR(mean, rho, 0.006) << rho;
  }
}

TEST(DrawBiasMaskTest, ExtremesDrawNothingAndOddSizesWork) {
  std::mt19937_64 rng(9), untouched(9);
  EXPECT_FALSE(DrawBiasMask({7, 3}, 0.0, rng).any().item<bool>());
  EXPECT_TRUE(DrawBiasMask({7, 3}, 1.0, rng).all().item<bool>());
  EXPECT_EQ(rng(), untouched());
  const at::Tensor odd = DrawBiasMask({5, 3}, 0.5, rng);
  EXPECT_EQ(odd.numel(), 15);
  EXPECT_EQ(odd.scalar_type(), at::kBool);
}

TEST(DrawBiasMaskTest, SeededAndDeterministic) {
  std::mt19937_64 a(5), b(5), c(6);
  const at::Tensor first = DrawBiasMask({64, 8}, 0.5, a);
  EXPECT_TRUE(at::equal(first, DrawBiasMask({64, 8}, 0.5, b)));
  EXPECT_FALSE(at::equal(first, DrawBiasMask({64, 8}, 0.5, c)));
}

TEST(AdvantageDtypeTest, Float32InputsGiveFloat32OutputsNearDouble) {
  const Rollout r = RandomRollout(300, 4, 0.02, 0.01, 9);
  AdvantageConfig config;
  config.statistic = *ParseStatistic("maxabs");
  config.rho = 0.5;
  std::mt19937_64 rng_a(1), rng_b(1);
  const Advantages f =
      *ComputeAdvantages(ToInputs(r, at::kFloat), config, rng_a);
  const Advantages d = *ComputeAdvantages(ToInputs(r), config, rng_b);
  EXPECT_EQ(f.gae.scalar_type(), at::kFloat);
  EXPECT_EQ(f.returns.scalar_type(), at::kFloat);
  EXPECT_TRUE(at::equal(f.mask, d.mask));
  EXPECT_TRUE(at::allclose(f.gae.to(at::kDouble), d.gae, 1e-4, 1e-4));
  EXPECT_TRUE(at::allclose(f.biased.to(at::kDouble), d.biased, 1e-4, 1e-4));
}

// ---------------------------------------------------------------------------
// Errors.

AdvantageInputs SmallInputs() {
  return ToInputs(RandomRollout(8, 2, 0.1, 0.1, 3));
}

TEST(AdvantageErrorTest, ShapeMismatchNamesTheTensor) {
  AdvantageInputs in = SmallInputs();
  in.values = at::zeros({8, 3}, at::kDouble);
  const absl::StatusOr<at::Tensor> gae = ComputeGae(in, 0.99, 0.95);
  ASSERT_FALSE(gae.ok());
  EXPECT_THAT(gae.status().message(),
              HasSubstr("values has shape [8, 3], expected [8, 2]"));

  in = SmallInputs();
  in.last_values = at::zeros({8}, at::kDouble);
  EXPECT_THAT(ComputeGae(in, 0.99, 0.95).status().message(),
              HasSubstr("last_values has shape [8], expected [2]"));

  in = SmallInputs();
  in.rewards = at::zeros({8}, at::kDouble);
  EXPECT_THAT(ComputeGae(in, 0.99, 0.95).status().message(),
              HasSubstr("rewards must be a non-empty [T, N] tensor"));

  in = SmallInputs();
  in.rewards = at::zeros({0, 2}, at::kDouble);
  EXPECT_FALSE(ComputeGae(in, 0.99, 0.95).ok());
}

TEST(AdvantageErrorTest, WrongDtypeAndMissingTensor) {
  AdvantageInputs in = SmallInputs();
  in.terminated = at::zeros({8, 2}, at::kFloat);
  EXPECT_THAT(ComputeGae(in, 0.99, 0.95).status().message(),
              HasSubstr("terminated has dtype Float, expected Bool"));
  in = SmallInputs();
  in.values = at::zeros({8, 2}, at::kLong);
  EXPECT_THAT(ComputeGae(in, 0.99, 0.95).status().message(),
              HasSubstr("values has dtype Long"));
  in = SmallInputs();
  in.truncated = at::Tensor();
  EXPECT_THAT(ComputeGae(in, 0.99, 0.95).status().message(),
              HasSubstr("truncated is missing"));
}

TEST(AdvantageErrorTest, ValidateFindsNonFiniteValues) {
  AdvantageInputs in = SmallInputs();
  EXPECT_TRUE(ValidateAdvantageInputs(in).ok());
  in.rewards[3][1] = std::nan("");
  EXPECT_THAT(ValidateAdvantageInputs(in).message(),
              HasSubstr("rewards has a non-finite value at index [3, 1]"));
  in = SmallInputs();
  in.last_values[0] = INFINITY;
  EXPECT_THAT(ValidateAdvantageInputs(in).message(),
              HasSubstr("last_values has a non-finite value at index [0]"));
}

TEST(AdvantageErrorTest, TruncationValuesMatterOnlyAtTruncatedSteps) {
  AdvantageInputs in = SmallInputs();
  in.truncated.fill_(false);
  in.truncation_values.fill_(std::nan(""));
  EXPECT_TRUE(ValidateAdvantageInputs(in).ok());
  const at::Tensor gae = *ComputeGae(in, 0.99, 0.95);
  EXPECT_TRUE(at::isfinite(gae).all().item<bool>());
  in.truncated[2][0] = true;
  EXPECT_THAT(ValidateAdvantageInputs(in).message(),
              HasSubstr("truncation_values (at a truncated step)"));
}

TEST(AdvantageErrorTest, InvalidConfigIsRefused) {
  AdvantageConfig config;
  config.rho = 2.0;
  EXPECT_THAT(ComputeBiasedAdvantage(SmallInputs(), config).status().message(),
              HasSubstr("rho must be in [0, 1]"));
  std::mt19937_64 rng(0);
  EXPECT_FALSE(ComputeAdvantages(SmallInputs(), config, rng).ok());
  EXPECT_THAT(
      ComputeKStepEstimates(SmallInputs(), 0.99, {4, 0}).status().message(),
      HasSubstr("k >= 1, got 0"));
}

TEST(AdvantageErrorTest, HugeKDoesNotOverflow) {
  const AdvantageInputs in = SmallInputs();
  const at::Tensor huge = *ComputeKStepEstimates(in, 0.99, {int64_t{1} << 62});
  const at::Tensor whole = *ComputeKStepEstimates(in, 0.99, {8});
  EXPECT_TRUE(at::equal(huge, whole));
}

}  // namespace
}  // namespace vantage
