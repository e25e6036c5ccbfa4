// Bad input gives a defined status with finite numbers: the same contract for the odometry's matcher
// (test_scan_matcher.cpp) and for every baseline of the evaluation library (test_baseline_matcher.cpp).
// Holds test definitions: include it from one source file per test binary, which instantiates BadInput.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>

#include "hglasm_odometry/core/scan_matcher.h"
#include "test_util.h"

namespace hglasm_test {

inline std::string describe(const hglasm::MatchResult& result) {
  std::ostringstream text;
  text << "pose " << result.pose.x << " " << result.pose.y << " " << result.pose.theta << ", prealigned "
       << result.prealigned_pose.x << " " << result.prealigned_pose.y << " " << result.prealigned_pose.theta
       << ", status " << hglasm::toString(result.status) << ", mbicp "
       << hglasm::toString(result.mbicp_status) << ", fitness ratio " << result.prealigned_fitness_ratio
       << ", evaluations " << result.evaluations << ", iterations " << result.iterations;
  return text.str();
}

inline void expectFinite(const hglasm::MatchResult& result) {
  EXPECT_TRUE(result.pose.isFinite()) << describe(result);
  EXPECT_TRUE(result.prealigned_pose.isFinite()) << describe(result);
  EXPECT_TRUE(isValidCovariance(result.covariance)) << result.covariance;
  EXPECT_TRUE(std::isfinite(result.prealigned_fitness_ratio));
  EXPECT_GE(result.prealigned_fitness_ratio, 0.0);
  EXPECT_LE(result.prealigned_fitness_ratio, 1.0);
  EXPECT_TRUE(std::isfinite(result.rms_error));
  EXPECT_TRUE(std::isfinite(result.prealign_ms) && result.prealign_ms >= 0.0);
  EXPECT_TRUE(std::isfinite(result.refine_ms) && result.refine_ms >= 0.0);
}

/// One matcher under the contract, behind one interface (ScanMatcher's match or refine, a baseline).
class MatcherUnderTest {
 public:
  virtual ~MatcherUnderTest() = default;
  virtual void setReference(const hglasm::Scan& reference) = 0;
  virtual bool hasReference() const = 0;
  virtual hglasm::MatchResult match(const hglasm::Scan& scan, const hglasm::Pose2D& guess) = 0;
};

struct MatcherCase {
  std::string name;
  bool refined = true;  ///< ends with MbICP: its tolerances, and the failures it must report
  std::function<std::unique_ptr<MatcherUnderTest>()> make;  ///< a new matcher (small preset)
};

/// gtest prints a case by its name (not its bytes).
inline void PrintTo(const MatcherCase& matcher_case, std::ostream* out) { *out << matcher_case.name; }

inline std::string matcherCaseName(const testing::TestParamInfo<MatcherCase>& info) {
  return info.param.name;
}

class BadInput : public testing::TestWithParam<MatcherCase> {
 protected:
  void SetUp() override {
    world_ = room();
    laser_ = halfCircleLaser();
    reference_ = simulateScan(world_, hglasm::Pose2D(), laser_);
  }
  std::unique_ptr<MatcherUnderTest> matcherWithReference() const {
    std::unique_ptr<MatcherUnderTest> matcher = GetParam().make();
    matcher->setReference(reference_);
    return matcher;
  }
  bool refined() const { return GetParam().refined; }
  hglasm::Scan convert(const hglasm::RangeScan& ranges) const { return hglasm::scanFromRanges(ranges); }

  World world_;
  LaserSpec laser_;
  hglasm::Scan reference_;
};

TEST_P(BadInput, MatchBeforeReference) {
  const std::unique_ptr<MatcherUnderTest> matcher = GetParam().make();
  EXPECT_FALSE(matcher->hasReference());
  const hglasm::MatchResult result = matcher->match(reference_, hglasm::Pose2D(0.1, 0.0, 0.0));
  EXPECT_EQ(result.status, hglasm::MatchStatus::kNoReference);
  EXPECT_FALSE(result.ok());
  expectFinite(result);
}

TEST_P(BadInput, EmptyReference) {
  const std::unique_ptr<MatcherUnderTest> matcher = GetParam().make();
  matcher->setReference(hglasm::Scan());
  EXPECT_FALSE(matcher->hasReference());
  const hglasm::MatchResult result = matcher->match(reference_, hglasm::Pose2D());
  EXPECT_EQ(result.status, hglasm::MatchStatus::kNoReference);
  expectFinite(result);
}

TEST_P(BadInput, EmptyScan) {
  const hglasm::MatchResult result =
      matcherWithReference()->match(hglasm::Scan(), hglasm::Pose2D(0.1, 0.2, 0.3));
  EXPECT_EQ(result.status, hglasm::MatchStatus::kTooFewPoints);
  expectFinite(result);
}

TEST_P(BadInput, AllRangesInvalid) {
  hglasm::RangeScan ranges = simulateRanges(world_, hglasm::Pose2D(), laser_);
  for (std::size_t i = 0; i < ranges.ranges.size(); ++i) {
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::infinity(),
                         -std::numeric_limits<float>::infinity(),
                         0.0f,
                         -1.0f,
                         1000.0f};
    ranges.ranges[i] = bad[i % 6];
  }
  const hglasm::MatchResult result = matcherWithReference()->match(convert(ranges), hglasm::Pose2D());
  EXPECT_EQ(result.status, hglasm::MatchStatus::kTooFewPoints);
  expectFinite(result);
}

TEST_P(BadInput, OnePointAndTwoPoints) {
  const std::unique_ptr<MatcherUnderTest> matcher = matcherWithReference();
  for (std::size_t count : {1u, 2u}) {
    hglasm::Scan few;
    few.points.assign(reference_.points.begin(), reference_.points.begin() + count);
    few.beam_index.assign(reference_.beam_index.begin(), reference_.beam_index.begin() + count);
    few.beam_count = 361;
    const hglasm::MatchResult result = matcher->match(few, hglasm::Pose2D());
    EXPECT_NE(result.status, hglasm::MatchStatus::kOk) << count << " points: " << describe(result);
    expectFinite(result);
  }
  // A one-point reference: nothing sensible to match against, but defined.
  hglasm::Scan one;
  one.points = {reference_.points[0]};
  one.beam_index = {0};
  const std::unique_ptr<MatcherUnderTest> tiny = GetParam().make();
  tiny->setReference(one);
  const hglasm::MatchResult result = tiny->match(reference_, hglasm::Pose2D());
  expectFinite(result);
  if (refined()) {
    EXPECT_NE(result.status, hglasm::MatchStatus::kOk) << describe(result);
  }
}

TEST_P(BadInput, NanAndInfRangesMixedIntoARealScanAreIgnored) {
  const hglasm::Pose2D truth(0.1, -0.05, 0.08);
  hglasm::RangeScan ranges = simulateRanges(world_, truth, laser_);
  const hglasm::Scan clean = convert(ranges);
  for (std::size_t i = 0; i < ranges.ranges.size(); i += 3) {
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::infinity(),
                         -std::numeric_limits<float>::infinity(),
                         0.0f,
                         -2.0f,
                         0.01f,
                         1e30f};
    ranges.ranges[i] = bad[(i / 3) % 7];
  }
  const hglasm::Scan dirty = convert(ranges);
  ASSERT_LT(dirty.size(), clean.size());
  ASSERT_GT(dirty.size(), clean.size() / 2);
  const hglasm::MatchResult result = matcherWithReference()->match(dirty, hglasm::Pose2D());
  expectFinite(result);
  EXPECT_EQ(result.status, hglasm::MatchStatus::kOk) << describe(result);
  EXPECT_LT(translationError(result.pose, truth), refined() ? 0.01 : 0.3) << describe(result);
  EXPECT_LT(rotationError(result.pose, truth), refined() ? deg(0.2) : 0.1) << describe(result);
}

TEST_P(BadInput, NonFinitePointsOrGuessGiveFiniteNumbers) {
  // A caller that bypasses scanFromRanges and hands over non-finite points or a non-finite guess.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  hglasm::Scan scan = simulateScan(world_, hglasm::Pose2D(0.05, 0.0, 0.0), laser_);
  for (std::size_t i = 0; i < scan.size(); i += 10) scan.points[i] = Eigen::Vector2d(nan, inf);
  const std::unique_ptr<MatcherUnderTest> matcher = matcherWithReference();
  expectFinite(matcher->match(scan, hglasm::Pose2D()));
  expectFinite(matcher->match(reference_, rawPose(nan, 0.0, 0.0)));
  expectFinite(matcher->match(reference_, rawPose(0.0, inf, -inf)));
  hglasm::Scan all_nan = scan;
  for (auto& p : all_nan.points) p = Eigen::Vector2d(nan, nan);
  const hglasm::MatchResult result = matcher->match(all_nan, hglasm::Pose2D());
  expectFinite(result);
  EXPECT_NE(result.status, hglasm::MatchStatus::kOk) << describe(result);
  // And a reference made of garbage.
  const std::unique_ptr<MatcherUnderTest> garbage = GetParam().make();
  garbage->setReference(all_nan);
  expectFinite(garbage->match(scan, hglasm::Pose2D()));
}

TEST_P(BadInput, FeaturelessCorridorDoesNotJump) {
  const World corridor_world = corridor(1.0, 200.0);
  const LaserSpec laser = laserSpec(deg(270.0), 541, false, 8.0);
  const std::unique_ptr<MatcherUnderTest> matcher = GetParam().make();
  matcher->setReference(simulateScan(corridor_world, hglasm::Pose2D(), laser));
  const hglasm::Pose2D truth(0.1, 0.02, 0.01);
  const hglasm::MatchResult result =
      matcher->match(simulateScan(corridor_world, truth, laser), hglasm::Pose2D(0.1, 0.0, 0.0));
  expectFinite(result);
  // Across the corridor and in heading the answer is determined; along it the estimate stays in the box.
  EXPECT_LT(std::abs(result.pose.x - 0.1), 0.3 + 1e-9) << describe(result);
  if (refined()) {
    EXPECT_NEAR(result.pose.y, truth.y, 0.01) << describe(result);
    EXPECT_TRUE(result.status == hglasm::MatchStatus::kMbicpFailed ||
                result.covariance(0, 0) > 100.0 * result.covariance(1, 1))
        << describe(result) << "\n"
        << result.covariance;
  }
}

}  // namespace hglasm_test
