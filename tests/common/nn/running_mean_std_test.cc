#include "common/nn/running_mean_std.h"

#include <ATen/ATen.h>

#include <cmath>
#include <limits>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

TEST(RunningMeanStdTest, BatchesMergeToTheStatisticsOfTheirUnion) {
  at::manual_seed(1);
  const at::Tensor all = at::randn({300, 4}, at::kDouble) * 3.0 + 2.0;
  RunningMeanStd stats(4, /*initial_count=*/1e-12);
  for (int begin = 0; begin < 300; begin += 70) {
    ASSERT_TRUE(
        stats.Update(all.slice(0, begin, std::min(300, begin + 70))).ok());
  }
  EXPECT_NEAR(stats.count(), 300.0, 1e-9);
  EXPECT_TRUE(at::allclose(stats.mean(), all.mean(0), 1e-9, 1e-9));
  EXPECT_TRUE(
      at::allclose(stats.var(), all.var(0, /*unbiased=*/false), 1e-9, 1e-9));
}

// A run that does not normalise keeps the initial statistics and an
// infinite clip: the networks then see the environment's floats exactly.
TEST(RunningMeanStdTest, TheInitialStatisticsWithoutAClipAreTheIdentity) {
  const RunningMeanStd stats(5);
  const at::Tensor x =
      at::tensor({-1e6f, -37.5f, 3.14159274f, 12.0f, 1e-7f}).reshape({1, 5});
  const at::Tensor passed =
      stats.Normalize(x, std::numeric_limits<double>::infinity());
  EXPECT_EQ(passed.scalar_type(), at::kFloat);
  EXPECT_TRUE(passed.equal(x)) << passed;
}

TEST(RunningMeanStdTest, NormalizesAndClips) {
  RunningMeanStd stats(2, 1e-12);
  ASSERT_TRUE(
      stats
          .Update(
              at::tensor({0.0, 10.0, 2.0, 10.0}, at::kDouble).reshape({2, 2}))
          .ok());
  // mean (1, 10), var (1, 0): the second column is only shifted.
  const at::Tensor x = at::tensor({3.0, 10.0}, at::kFloat).reshape({1, 2});
  const at::Tensor normalized = stats.Normalize(x, 1.5);
  EXPECT_EQ(normalized.scalar_type(), at::kFloat);
  EXPECT_FLOAT_EQ(normalized[0][0].item<float>(), 1.5f);  // 2 clipped to 1.5
  EXPECT_NEAR(normalized[0][1].item<float>(), 0.0f, 1e-6);
}

TEST(RunningMeanStdTest, BadInputLeavesTheStatisticsAlone) {
  RunningMeanStd stats(3);
  const at::Tensor mean = stats.mean().clone();
  EXPECT_THAT(stats.Update(at::zeros({2, 4})).message(),
              HasSubstr("needs [B, 3]"));
  at::Tensor bad = at::zeros({2, 3});
  bad[1][2] = NAN;
  EXPECT_THAT(stats.Update(bad).message(), HasSubstr("non-finite"));
  EXPECT_TRUE(at::equal(stats.mean(), mean));
  EXPECT_FALSE(stats.Restore(0.0, mean, stats.var()).ok());
  EXPECT_FALSE(stats.Restore(5.0, at::zeros({2}), stats.var()).ok());
  EXPECT_FALSE(stats.Restore(5.0, mean, -at::ones({3})).ok());
  EXPECT_TRUE(stats.Restore(5.0, at::ones({3}), at::ones({3}) * 4).ok());
  EXPECT_EQ(stats.count(), 5.0);
}

}  // namespace
}  // namespace vantage
