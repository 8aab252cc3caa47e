#include "common/advantage/estimator_kernels.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "gtest/gtest.h"

namespace vantage {
namespace {

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

TEST(SortingNetworkTest, NoPairsBelowTwoInputs) {
  EXPECT_TRUE(SortingNetwork(0).empty());
  EXPECT_TRUE(SortingNetwork(1).empty());
  EXPECT_EQ(SortingNetwork(2).size(), 1u);
}

// The fused, blocked and vectorised statistic kernel against a plain
// reduction of KStepKernel's columns: stream counts that are and are not
// multiples of the vector width, rollouts longer than a block, members that
// collapse part-way through a vector chunk.
TEST(EnsembleStatisticKernelTest, MatchesPlainReductionOfKStepColumns) {
  const double gamma = 0.9;
  for (const int64_t streams : {1, 3, 4, 16}) {
    for (const int64_t steps : {1, 5, 300, 1100}) {
      const int64_t total = steps * streams;
      std::vector<double> delta(total), continues(total);
      for (int64_t i = 0; i < total; ++i) {
        delta[i] = ((i * 7919) % 113) / 10.0 - 5.0;
        const int64_t t = i / streams;
        // Episodes of length 37, offset per stream; the last row ends.
        const bool ends = (t + i % streams) % 37 == 36 || t == steps - 1;
        continues[i] = ends ? 0.0 : 1.0;
      }
      std::vector<double> longest(total), remaining(total);
      ComputePathEnsembleBasis(steps, streams, delta.data(), continues.data(),
                               gamma, longest.data(), remaining.data());
      const PathEnsembleBasis basis{longest.data(), remaining.data()};
      for (const std::vector<int64_t>& ensemble :
           std::vector<std::vector<int64_t>>{
               {1}, {1, 2, 5, 9, 30, 500}, {3, 64, 2048}, {2, 1000000}}) {
        std::vector<std::vector<double>> columns;
        for (int64_t k : ensemble) {
          columns.emplace_back(total);
          KStepKernel(basis, steps, streams, k, gamma, columns.back().data());
        }
        std::vector<Statistic> statistics = {{StatisticKind::kMax, 0},
                                             {StatisticKind::kMin, 0},
                                             {StatisticKind::kMaxAbs, 0}};
        for (int d = 1; d <= static_cast<int>(ensemble.size()); ++d) {
          statistics.push_back({StatisticKind::kOrder, d});
        }
        for (const Statistic& statistic : statistics) {
          std::vector<double> out(total), fused_longest(total),
              fused_remaining(total);
          EnsembleStatisticKernel(steps, streams, delta.data(),
                                  continues.data(), gamma, ensemble, statistic,
                                  fused_longest.data(), fused_remaining.data(),
                                  out.data());
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

}  // namespace
}  // namespace vantage
