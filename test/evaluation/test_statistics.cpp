// The one implementation of median, nearest-rank percentile, mean and the spread the tools print.
#include "hglasm_odometry/evaluation/statistics.h"

#include <gtest/gtest.h>

#include <vector>

namespace hglasm {
namespace {

TEST(Statistics, KthSmallestClampsAndIsZeroForNoValues) {
  EXPECT_EQ(kthSmallest({5.0, 1.0, 3.0}, 0), 1.0);
  EXPECT_EQ(kthSmallest({5.0, 1.0, 3.0}, 1), 3.0);
  EXPECT_EQ(kthSmallest({5.0, 1.0, 3.0}, 7), 5.0);
  EXPECT_EQ(kthSmallest({}, 0), 0.0);
}

TEST(Statistics, MedianIsTheMiddleOrTheMeanOfTheTwoMiddleValues) {
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(median({7.0}), 7.0);
  EXPECT_EQ(median({}), 0.0);
}

TEST(Statistics, PercentileIsTheNearestRank) {
  std::vector<double> values;
  for (int i = 100; i >= 1; --i) values.push_back(i);  // 1..100, unsorted
  EXPECT_EQ(percentile(values, 0.99), 99.0);
  EXPECT_EQ(percentile(values, 0.5), 50.0);
  EXPECT_EQ(percentile(values, 0.001), 1.0);
  EXPECT_EQ(percentile(values, 0.0), 1.0);
  EXPECT_EQ(percentile(values, 1.0), 100.0);
  EXPECT_EQ(percentile({1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0}, 0.99), 10.0);  // a small sample
  EXPECT_EQ(percentile({}, 0.5), 0.0);
}

TEST(Statistics, MeanOfNoValuesIsZero) {
  EXPECT_EQ(mean({1.0, 2.0, 6.0}), 3.0);
  EXPECT_EQ(mean({}), 0.0);
}

TEST(Statistics, SpreadHoldsCountMedianP99MaxAndMean) {
  std::vector<double> values;
  for (int i = 0; i < 200; ++i) values.push_back((i * 7) % 200 + 1);  // 1..200, scrambled
  const Spread spread = spreadOf(values);
  EXPECT_EQ(spread.count, 200u);
  EXPECT_EQ(spread.median, 100.5);
  EXPECT_EQ(spread.p99, 198.0);
  EXPECT_EQ(spread.max, 200.0);
  EXPECT_EQ(spread.mean, 100.5);
  const Spread none = spreadOf({});
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(none.max, 0.0);
}

}  // namespace
}  // namespace hglasm
