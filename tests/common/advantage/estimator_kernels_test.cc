#include "common/advantage/estimator_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "common/advantage/estimator_kernels_isa.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

// Owns the arrays behind a RolloutView.
template <typename Scalar>
struct OwnedRollout {
  OwnedRollout(int64_t steps, int64_t streams)
      : steps(steps),
        streams(streams),
        rewards(steps * streams),
        values(steps * streams),
        truncation_values(steps * streams),
        last_values(streams),
        terminated(new bool[steps * streams]()),
        truncated(new bool[steps * streams]()) {}

  RolloutView<Scalar> View() const {
    RolloutView<Scalar> view;
    view.steps = steps;
    view.streams = streams;
    view.rewards = rewards.data();
    view.values = values.data();
    view.terminated = terminated.get();
    view.truncated = truncated.get();
    view.truncation_values = truncation_values.data();
    view.last_values = last_values.data();
    return view;
  }

  int64_t steps;
  int64_t streams;
  std::vector<Scalar> rewards, values, truncation_values, last_values;
  std::unique_ptr<bool[]> terminated, truncated;
};

// By the 0-1 principle a comparator network sorts every input iff it sorts
// every 0/1 input.
TEST(SortingNetworkTest, SortsEveryBinaryInput) {
  for (int n = 1; n <= 14; ++n) {
    const auto network = SortingNetwork(n);
    for (int bits = 0; bits < (1 << n); ++bits) {
      std::vector<int> values(n);
      for (int i = 0; i < n; ++i) values[i] = (bits >> i) & 1;
      for (const auto& [a, b] : network) {
        ASSERT_LT(a, b);
        ASSERT_LT(b, n);
        if (values[b] < values[a]) std::swap(values[a], values[b]);
      }
      ASSERT_TRUE(std::is_sorted(values.begin(), values.end()))
          << "n=" << n << " input bits=" << bits;
    }
  }
}

// The 0-1 principle holds for selection networks too.
TEST(SelectionNetworkTest, SelectsEveryRankOfEveryBinaryInput) {
  for (int n = 1; n <= 13; ++n) {
    for (int position = 0; position < n; ++position) {
      const auto network = SelectionNetwork(n, position);
      EXPECT_LE(network.size(), SortingNetwork(n).size());
      for (int bits = 0; bits < (1 << n); ++bits) {
        std::vector<int> values(n);
        for (int i = 0; i < n; ++i) values[i] = (bits >> i) & 1;
        std::vector<int> sorted = values;
        std::sort(sorted.begin(), sorted.end());
        for (const auto& [a, b] : network) {
          if (values[b] < values[a]) std::swap(values[a], values[b]);
        }
        ASSERT_EQ(values[position], sorted[position])
            << "n=" << n << " position=" << position << " bits=" << bits;
      }
    }
  }
  // Pruning pays off at the extremes: the minimum of 12 needs 11 pairs.
  EXPECT_EQ(SelectionNetwork(12, 0).size(), 11u);
}

TEST(SortingNetworkTest, NoPairsBelowTwoInputs) {
  EXPECT_TRUE(SortingNetwork(0).empty());
  EXPECT_TRUE(SortingNetwork(1).empty());
  EXPECT_EQ(SortingNetwork(2).size(), 1u);
}

// The fused, blocked and vectorised pass against a plain reduction of
// KStepFromBasis' columns: stream counts that are and are not multiples of
// the vector width, rollouts shorter and longer than a block, members that
// collapse part-way through a block.
TEST(RunEstimatorsTest, StatisticMatchesPlainReductionOfKStepColumns) {
  const double gamma = 0.9;
  for (const int64_t streams : {1, 3, 4, 16}) {
    for (const int64_t steps : {1, 5, 300, 1100}) {
      const int64_t total = steps * streams;
      OwnedRollout<double> owned(steps, streams);
      std::fill(owned.last_values.begin(), owned.last_values.end(), 0.5);
      for (int64_t i = 0; i < total; ++i) {
        owned.rewards[i] = ((i * 7919) % 113) / 10.0 - 5.0;
        owned.values[i] = ((i * 104729) % 37) / 7.0 - 2.0;
        owned.truncation_values[i] = 1.5;
        const int64_t t = i / streams;
        // Episodes of length 37, offset per stream, some cut by time limits.
        owned.terminated[i] = (t + i % streams) % 37 == 36;
        owned.truncated[i] = (t + 2 * (i % streams)) % 53 == 52;
      }
      const RolloutView<double> rollout = owned.View();

      std::vector<double> longest(total), remaining(total);
      EstimatorSettings basis_only;
      basis_only.gamma = gamma;
      EstimatorOutputs<double> basis_outputs;
      basis_outputs.longest = longest.data();
      basis_outputs.remaining = remaining.data();
      RunEstimators(rollout, basis_only, basis_outputs);

      for (const std::vector<int64_t>& ensemble :
           std::vector<std::vector<int64_t>>{
               {1}, {1, 2, 5, 9, 30, 500}, {3, 64, 2048}, {2, 1000000}}) {
        std::vector<std::vector<double>> columns;
        for (int64_t k : ensemble) {
          columns.emplace_back(total);
          KStepFromBasis(longest.data(), remaining.data(), steps, streams, k,
                         gamma, columns.back().data());
        }
        std::vector<Statistic> statistics = {{StatisticKind::kMax, 0},
                                             {StatisticKind::kMin, 0},
                                             {StatisticKind::kMaxAbs, 0}};
        for (int d = 1; d <= static_cast<int>(ensemble.size()); ++d) {
          statistics.push_back({StatisticKind::kOrder, d});
        }
        for (const Statistic& statistic : statistics) {
          EstimatorSettings settings;
          settings.gamma = gamma;
          settings.ensemble = ensemble;
          settings.statistic = statistic;
          std::vector<double> out(total), fused_longest(total),
              fused_remaining(total);
          EstimatorOutputs<double> outputs;
          outputs.biased = out.data();
          outputs.longest = fused_longest.data();
          outputs.remaining = fused_remaining.data();
          RunEstimators(rollout, settings, outputs);
          ASSERT_EQ(fused_longest, longest);
          ASSERT_EQ(fused_remaining, remaining);
          for (int64_t i = 0; i < total; ++i) {
            std::vector<double> members;
            for (const auto& column : columns) members.push_back(column[i]);
            double expected = members[0];
            switch (statistic.kind) {
              case StatisticKind::kMax:
                expected = *std::max_element(members.begin(), members.end());
                break;
              case StatisticKind::kMin:
                expected = *std::min_element(members.begin(), members.end());
                break;
              case StatisticKind::kMaxAbs:
                for (double a : members) {
                  if (std::fabs(a) > std::fabs(expected)) expected = a;
                }
                break;
              case StatisticKind::kOrder:
                std::sort(members.begin(), members.end());
                expected = members[statistic.order - 1];
                break;
              case StatisticKind::kGae:
                break;
            }
            ASSERT_EQ(out[i], expected)
                << StatisticName(statistic) << " i=" << i
                << " streams=" << streams << " steps=" << steps;
          }
        }
      }
    }
  }
}

// Every instruction-set copy of the kernels must give the same bits, or
// results would depend on the machine a learner runs on.
TEST(KernelIsaTest, EveryCopyGivesIdenticalBits) {
#if !defined(VANTAGE_HAVE_AVX2_KERNELS)
  GTEST_SKIP() << "this build has only the baseline kernels";
#else
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "CPU without AVX2";
  const int64_t steps = 700;
  const int64_t streams = 7;
  const int64_t total = steps * streams;
  std::mt19937_64 rng(3);
  std::normal_distribution<float> normal;
  std::bernoulli_distribution rare(0.01);
  OwnedRollout<float> owned(steps, streams);
  for (int64_t i = 0; i < total; ++i) {
    owned.rewards[i] = normal(rng);
    owned.values[i] = 5.0f * normal(rng);
    owned.truncation_values[i] = normal(rng);
    owned.terminated[i] = rare(rng);
    owned.truncated[i] = rare(rng);
  }
  for (float& v : owned.last_values) v = normal(rng);
  const RolloutView<float> rollout = owned.View();
  for (const char* name : {"max", "min", "maxabs", "order:3", "order:7"}) {
    EstimatorSettings settings;
    settings.ensemble = {1, 2, 4, 8, 16, 64, 256, 2048};
    settings.statistic = *ParseStatistic(name);
    std::vector<float> gae[2], biased[2];
    std::vector<double> longest[2], remaining[2];
    for (int copy = 0; copy < 2; ++copy) {
      gae[copy].resize(total);
      biased[copy].resize(total);
      longest[copy].resize(total);
      remaining[copy].resize(total);
      EstimatorOutputs<float> outputs;
      outputs.gae = gae[copy].data();
      outputs.biased = biased[copy].data();
      outputs.longest = longest[copy].data();
      outputs.remaining = remaining[copy].data();
      if (copy == 0) {
        isa_baseline::RunEstimators(rollout, settings, outputs);
      } else {
        isa_avx2::RunEstimators(rollout, settings, outputs);
      }
    }
    EXPECT_EQ(std::memcmp(gae[0].data(), gae[1].data(), total * 4), 0);
    EXPECT_EQ(std::memcmp(biased[0].data(), biased[1].data(), total * 4), 0)
        << name;
    EXPECT_EQ(std::memcmp(longest[0].data(), longest[1].data(), total * 8), 0);
  }
#endif
}

}  // namespace
}  // namespace vantage
