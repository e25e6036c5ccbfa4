// The tables a local map keeps and the one scans are judged on, a scan's fitness ratio and likelihoods on
// it, and the running statistics of how well matches usually fit.
#include "hglasm_odometry/core/fitness_monitor.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"

namespace {

using hglasm::FitnessMonitor;
using hglasm::Pose2D;

TEST(FitnessMonitor, MapTablesAreTheGasFineAndCoarseTables) {
  hglasm::MatcherOptions matcher;
  matcher.table.cell_size = 0.03;
  const auto tables = hglasm::mapTables(matcher);
  ASSERT_EQ(tables.size(), 2u);
  EXPECT_EQ(tables[hglasm::kFineTable].cell_size, 0.03);
  EXPECT_EQ(tables[hglasm::kCoarseTable].cell_size, hglasm::coarseTableOptions().cell_size);
}

TEST(FitnessMonitor, TheJudgingTableIsTheFineOne) {
  hglasm::LocalMap map({}, hglasm::mapTables(hglasm::MatcherOptions()));
  map.add(Pose2D(), {Eigen::Vector2d(2.0, 0.0), Eigen::Vector2d(2.0, 0.05)});
  const hglasm::LookupTable& judging = hglasm::judgingTable(map);
  EXPECT_EQ(&judging, &map.table(hglasm::kFineTable));
  EXPECT_EQ(judging.options().cell_size, hglasm::LookupTableOptions().cell_size);
  EXPECT_EQ(judging.maxCellValue(), 255u);
  EXPECT_FALSE(judging.empty());
}

TEST(FitnessMonitor, LikelihoodWeightCountsTheIndependentPointsOverTheEvidenceScale) {
  EXPECT_DOUBLE_EQ(hglasm::likelihoodWeight(100.0, 400, 1.0), 0.25);
  EXPECT_DOUBLE_EQ(hglasm::likelihoodWeight(100.0, 400, 2.0), 0.125);
  EXPECT_DOUBLE_EQ(hglasm::likelihoodWeight(100.0, 50, 1.0), 1.0) << "never more than every point";
  EXPECT_DOUBLE_EQ(hglasm::likelihoodWeight(0.0, 400, 4.0), 0.25) << "0: every point counts";
}

/// A room scanned from the origin, its points as the map and as the scan.
struct Judged {
  hglasm::Scan scan =
      hglasm_test::simulateScan(hglasm_test::room(), Pose2D(), hglasm_test::fullCircleLaser());
  hglasm::LookupTable table;
  Judged() { table.build(scan.points); }
};

TEST(FitnessMonitor, AScanJudgedWhereItWasTakenFitsAndLikesBest) {
  const Judged judged;
  const hglasm::ScanJudge judge(judged.table, judged.scan, 0.5, 0.1);
  EXPECT_GT(judge.fitnessRatio(Pose2D()), 0.95);
  EXPECT_LE(judge.fitnessRatio(Pose2D()), 1.0);
  const Pose2D off(0.5, 0.0, 0.2);
  EXPECT_LT(judge.fitnessRatio(off), 0.5);
  EXPECT_GT(judge.logLikelihood(Pose2D()), judge.logLikelihood(off));
  // Moved half a metre, more beams of the scan cross the map's surfaces than where it was taken, each
  // costing log(outlier), weighted.
  const double at_truth = judge.freeSpaceLogLikelihood(Pose2D());
  const double crossing = judge.freeSpaceLogLikelihood(off);
  EXPECT_LT(crossing, at_truth);
  const double beams = crossing / (0.5 * std::log(0.1));
  EXPECT_GE(beams, 1.0);
  EXPECT_NEAR(beams, std::round(beams), 1e-9) << "whole beams";
}

TEST(FitnessMonitor, AJudgeWithoutTableOrPointsSaysNothing) {
  const hglasm::LookupTable empty_table;
  const hglasm::Scan scan = Judged().scan;
  const hglasm::ScanJudge no_table(empty_table, scan, 1.0, 0.1);
  EXPECT_EQ(no_table.fitnessRatio(Pose2D()), 0.0);
  EXPECT_EQ(no_table.logLikelihood(Pose2D()), 0.0);
  const Judged judged;
  const hglasm::Scan no_points;
  const hglasm::ScanJudge empty_scan(judged.table, no_points, 1.0, 0.1);
  EXPECT_EQ(empty_scan.fitnessRatio(Pose2D()), 0.0);
  EXPECT_EQ(empty_scan.freeSpaceLogLikelihood(Pose2D(1.0, 0.0, 0.0)), 0.0);
  const hglasm::ScanJudge no_outliers(judged.table, judged.scan, 1.0, 0.0);
  EXPECT_EQ(no_outliers.freeSpaceLogLikelihood(Pose2D(0.5, 0.0, 0.2)), 0.0);
}

TEST(FitnessMonitor, EveryFitIsUsualUntilFiveMatchesAreKnown) {
  FitnessMonitor monitor(4.0);
  for (int i = 0; i < FitnessMonitor::kMinHistory; ++i) {
    EXPECT_TRUE(monitor.usual(0.0)) << i;
    monitor.add(0.9);
  }
  EXPECT_FALSE(monitor.usual(0.5));
  EXPECT_TRUE(monitor.usual(0.9));
  monitor.reset();
  EXPECT_EQ(monitor.count(), 0);
  EXPECT_TRUE(monitor.usual(0.0));
}

TEST(FitnessMonitor, MeanAndVarianceAreExponentiallyForgotten) {
  FitnessMonitor monitor(4.0);
  monitor.add(1.0);
  EXPECT_EQ(monitor.mean(), 1.0);
  EXPECT_EQ(monitor.variance(), 0.0);
  monitor.add(0.0);  // the second counts half
  EXPECT_DOUBLE_EQ(monitor.mean(), 0.5);
  EXPECT_DOUBLE_EQ(monitor.variance(), 0.25);
  // Long after, each new value weighs 1 - 2^(-1/50): a step in the scene is half forgotten in 50 matches.
  FitnessMonitor drifting(4.0);
  for (int i = 0; i < 500; ++i) drifting.add(0.9);
  for (int i = 0; i < 50; ++i) drifting.add(0.5);
  EXPECT_NEAR(drifting.mean(), 0.7, 1e-9);
  // A fit 4 standard deviations below the mean is still usual; farther is not.
  const double sigma = std::sqrt(drifting.variance());
  EXPECT_TRUE(drifting.usual(drifting.mean() - 3.9 * sigma));
  EXPECT_FALSE(drifting.usual(drifting.mean() - 4.1 * sigma));
}

}  // namespace
