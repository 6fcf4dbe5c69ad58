#include <gtest/gtest.h>

#include <pcg_random.hpp>
#include <random>

#include "observers/block_average.hpp"

using namespace hb;

TEST(BlockAverage, UncorrelatedErrorMatchesSigmaOverSqrtN) {
  pcg32 rng(3);
  std::normal_distribution<double> g(5.0, 2.0);
  std::vector<double> x(4096);
  for (auto& v : x) v = g(rng);
  const auto r = block_average(x);
  EXPECT_NEAR(r.mean, 5.0, 4 * 2.0 / 64.0);
  EXPECT_NEAR(r.error, 2.0 / 64.0, 0.3 * 2.0 / 64.0);
}

TEST(BlockAverage, CorrelatedSeriesErrorGrows) {
  // AR(1) with correlation 0.9: true error of the mean is sqrt((1+a)/(1-a)) ~ 4.36 times naive.
  pcg32 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> x(1 << 16);
  double y = 0.0;
  for (auto& v : x) v = y = 0.9 * y + g(rng);
  double m = 0, q = 0;
  for (double v : x) m += v;
  m /= x.size();
  for (double v : x) q += (v - m) * (v - m);
  const double naive = std::sqrt(q / x.size() / (x.size() - 1));
  const auto r = block_average(x);
  EXPECT_GT(r.error / naive, 3.5);
  EXPECT_LT(r.error / naive, 5.5);
}

// Below two blocks the error of the mean is unknown: NaN (null in summary.json), not 0 (a run of
// one log block once reported "Z +- 0.00000").
TEST(BlockAverage, ErrorIsUnknownBelowTwoBlocks) {
  EXPECT_FALSE(block_average({}).error_known());
  const auto one = block_average({3.0});
  EXPECT_EQ(one.mean, 3.0);
  EXPECT_FALSE(one.error_known());
  EXPECT_TRUE(std::isnan(one.error));
  const auto two = block_average({3.0, 5.0});
  EXPECT_TRUE(two.error_known());
  EXPECT_DOUBLE_EQ(two.error, 1.0);
}
