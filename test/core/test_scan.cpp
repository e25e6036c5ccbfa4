// Scan conversion: REP-117 validity, descending and 360-degree scans, any beam count, mirror, decimation,
// structurally broken scans, beam parity selection, transforms, beam times and motion compensation.
#include "hglasm_odometry/core/scan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <set>

#include "test_util.h"

namespace {

using hglasm::RangeScan;
using hglasm::Scan;
using hglasm::ScanConversionOptions;
using hglasm::ScanError;
using hglasm_test::kPi;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

RangeScan makeRanges(std::vector<float> ranges, double angle_min, double increment, double range_min = 0.1,
                     double range_max = 20.0) {
  RangeScan scan;
  scan.ranges = std::move(ranges);
  scan.angle_min = angle_min;
  scan.angle_increment = increment;
  scan.range_min = range_min;
  scan.range_max = range_max;
  return scan;
}

void expectPoint(const Eigen::Vector2d& actual, double x, double y, double tolerance = 1e-6) {
  EXPECT_NEAR(actual.x(), x, tolerance);
  EXPECT_NEAR(actual.y(), y, tolerance);
}

TEST(ScanFromRanges, PolarToCartesian) {
  ScanError error = ScanError::kNoBeams;
  const Scan scan = hglasm::scanFromRanges(makeRanges({1.0f, 2.0f, 3.0f}, 0.0, kPi / 2.0), {}, &error);
  EXPECT_EQ(error, ScanError::kNone);
  ASSERT_EQ(scan.size(), 3u);
  EXPECT_EQ(scan.beam_count, 3);
  EXPECT_EQ(scan.invalid_count, 0);
  expectPoint(scan.points[0], 1.0, 0.0);
  expectPoint(scan.points[1], 0.0, 2.0);
  expectPoint(scan.points[2], -3.0, 0.0);
  EXPECT_EQ(scan.beam_index, (std::vector<int>{0, 1, 2}));
}

TEST(ScanFromRanges, Rep117InvalidRangesAreDropped) {
  // NaN, +inf, -inf, zero, negative, below range_min, above range_max, then one valid reading.
  const Scan scan = hglasm::scanFromRanges(
      makeRanges({kNaN, kInf, -kInf, 0.0f, -1.0f, 0.05f, 30.0f, 1.5f}, -0.7, 0.2, 0.1, 20.0));
  EXPECT_EQ(scan.beam_count, 8);
  EXPECT_EQ(scan.invalid_count, 7);
  ASSERT_EQ(scan.size(), 1u);
  EXPECT_EQ(scan.beam_index[0], 7);
  expectPoint(scan.points[0], 1.5 * std::cos(-0.7 + 7 * 0.2), 1.5 * std::sin(-0.7 + 7 * 0.2));
  for (const auto& p : scan.points) EXPECT_TRUE(p.allFinite());
}

TEST(ScanFromRanges, LimitsAreInclusive) {
  const Scan scan = hglasm::scanFromRanges(makeRanges({0.5f, 10.0f, 0.49f, 10.01f}, 0.0, 0.1, 0.5, 10.0));
  EXPECT_EQ(scan.beam_index, (std::vector<int>{0, 1}));
}

TEST(ScanFromRanges, NoRangeLimitsStillRejectsNonPositiveAndNonFinite) {
  RangeScan ranges;  // range_min 0, range_max inf: the defaults
  ranges.ranges = {0.0f, -0.0f, -2.0f, kNaN, kInf, 1e-3f, 100.0f};
  ranges.angle_min = 0.0;
  ranges.angle_increment = 0.01;
  const Scan scan = hglasm::scanFromRanges(ranges);
  EXPECT_EQ(scan.beam_index, (std::vector<int>{5, 6}));
}

TEST(ScanFromRanges, OptionsNarrowTheRangeLimits) {
  ScanConversionOptions options;
  options.min_range = 1.0;
  options.max_range = 5.0;
  const Scan scan =
      hglasm::scanFromRanges(makeRanges({0.5f, 1.0f, 3.0f, 5.0f, 6.0f, 15.0f}, 0.0, 0.1, 0.1, 20.0), options);
  EXPECT_EQ(scan.beam_index, (std::vector<int>{1, 2, 3}));
  // Options never widen the sensor's own limits.
  options.min_range = 0.0;
  options.max_range = 100.0;
  const Scan wide = hglasm::scanFromRanges(makeRanges({0.05f, 1.0f, 25.0f}, 0.0, 0.1, 0.1, 20.0), options);
  EXPECT_EQ(wide.beam_index, (std::vector<int>{1}));
}

TEST(ScanFromRanges, DescendingAnglesKeepBeamOrder) {
  const Scan scan = hglasm::scanFromRanges(makeRanges({1.0f, 2.0f, 3.0f}, kPi / 2.0, -kPi / 2.0));
  ASSERT_EQ(scan.size(), 3u);
  expectPoint(scan.points[0], 0.0, 1.0);
  expectPoint(scan.points[1], 2.0, 0.0);
  expectPoint(scan.points[2], 0.0, -3.0);
  EXPECT_EQ(scan.beam_index, (std::vector<int>{0, 1, 2}));
}

TEST(ScanFromRanges, DescendingAndAscendingScansOfTheSameRoomGiveTheSamePoints) {
  const hglasm_test::World world = hglasm_test::room();
  const hglasm::Pose2D pose(0.3, -0.2, 0.4);
  const Scan up = hglasm::scanFromRanges(
      hglasm_test::simulateRanges(world, pose, hglasm_test::laserSpec(kPi, 181, false)));
  const Scan down = hglasm::scanFromRanges(
      hglasm_test::simulateRanges(world, pose, hglasm_test::laserSpec(kPi, 181, true)));
  ASSERT_EQ(up.size(), down.size());
  ASSERT_EQ(up.size(), 181u);
  for (std::size_t i = 0; i < up.size(); ++i) {
    // Beam i of the descending scan is beam n-1-i of the ascending one.
    EXPECT_NEAR((up.points[i] - down.points[up.size() - 1 - i]).norm(), 0.0, 1e-5);
  }
}

TEST(ScanFromRanges, FullCircleAcrossTheSeam) {
  // 360 beams from -pi: every direction once, including the seam between beams 359 and 0.
  std::vector<float> ranges(360, 2.0f);
  const Scan scan = hglasm::scanFromRanges(makeRanges(ranges, -kPi, 2.0 * kPi / 360.0));
  ASSERT_EQ(scan.size(), 360u);
  expectPoint(scan.points[0], -2.0, 0.0);
  expectPoint(scan.points[180], 2.0, 0.0);
  expectPoint(scan.points[90], 0.0, -2.0);
  for (const auto& p : scan.points) EXPECT_NEAR(p.norm(), 2.0, 1e-6);
  // Angles past +pi (a scan starting at 0 and going round) are just as valid.
  const Scan from_zero = hglasm::scanFromRanges(makeRanges(ranges, 0.0, 2.0 * kPi / 360.0));
  ASSERT_EQ(from_zero.size(), 360u);
  expectPoint(from_zero.points[270], 0.0, -2.0);
  expectPoint(from_zero.points[359], 2.0 * std::cos(-kPi / 180.0), 2.0 * std::sin(-kPi / 180.0));
}

TEST(ScanFromRanges, AnyBeamCount) {
  for (int beams : {1, 2, 3, 180, 181, 360, 361, 681, 1081, 2161, 4000}) {
    const double increment = beams > 1 ? kPi / (beams - 1) : 0.0;  // one beam: increment may be zero
    std::vector<float> ranges(beams, 4.0f);
    ScanError error = ScanError::kNoBeams;
    const Scan scan = hglasm::scanFromRanges(makeRanges(ranges, -kPi / 2.0, increment), {}, &error);
    EXPECT_EQ(error, ScanError::kNone) << beams;
    ASSERT_EQ(static_cast<int>(scan.size()), beams);
    EXPECT_EQ(scan.beam_count, beams);
    expectPoint(scan.points.front(), 0.0, -4.0);
    if (beams > 1) expectPoint(scan.points.back(), 0.0, 4.0);
  }
}

TEST(ScanFromRanges, SimulatedRoomScanMatchesTheTestConversion) {
  const hglasm_test::World world = hglasm_test::room();
  const hglasm::Pose2D pose(-0.5, 0.7, -2.0);
  for (const auto& spec : {hglasm_test::halfCircleLaser(), hglasm_test::fullCircleLaser(),
                           hglasm_test::laserSpec(hglasm_test::deg(239.0), 681, true, 5.6)}) {
    const Scan core = hglasm::scanFromRanges(hglasm_test::simulateRanges(world, pose, spec));
    const Scan reference = hglasm_test::simulateScan(world, pose, spec);
    ASSERT_EQ(core.size(), reference.size());
    EXPECT_EQ(core.beam_index, reference.beam_index);
    EXPECT_EQ(core.invalid_count, reference.invalid_count);
    for (std::size_t i = 0; i < core.size(); ++i) {
      EXPECT_NEAR((core.points[i] - reference.points[i]).norm(), 0.0, 1e-5);
    }
  }
}

TEST(ScanFromRanges, MirrorNegatesAngles) {
  ScanConversionOptions options;
  options.mirror = true;
  const RangeScan ranges = makeRanges({1.0f, 2.0f, 3.0f}, 0.2, 0.5);
  const Scan plain = hglasm::scanFromRanges(ranges);
  const Scan mirrored = hglasm::scanFromRanges(ranges, options);
  ASSERT_EQ(mirrored.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    expectPoint(mirrored.points[i], plain.points[i].x(), -plain.points[i].y());
  }
  EXPECT_EQ(mirrored.beam_index, plain.beam_index);
}

TEST(ScanFromRanges, DecimationKeepsEveryNthBeamAndItsIndex) {
  std::vector<float> ranges(10, 1.0f);
  ranges[4] = kNaN;
  ScanConversionOptions options;
  options.beam_step = 2;
  const Scan scan = hglasm::scanFromRanges(makeRanges(ranges, 0.0, 0.1), options);
  EXPECT_EQ(scan.beam_index, (std::vector<int>{0, 2, 6, 8}));
  EXPECT_EQ(scan.beam_count, 10);
  expectPoint(scan.points[2], std::cos(0.6), std::sin(0.6));
  options.beam_step = 3;
  EXPECT_EQ(hglasm::scanFromRanges(makeRanges(ranges, 0.0, 0.1), options).beam_index,
            (std::vector<int>{0, 3, 6, 9}));
}

TEST(ScanFromRanges, NonPositiveBeamStepDoesNotCrash) {
  for (int step : {0, -1, -100}) {
    ScanConversionOptions options;
    options.beam_step = step;
    const Scan scan = hglasm::scanFromRanges(makeRanges({1.0f, 2.0f, 3.0f}, 0.0, 0.1), options);
    EXPECT_LE(scan.size(), 3u);
    for (const auto& p : scan.points) EXPECT_TRUE(p.allFinite());
  }
}

TEST(ScanFromRanges, StructurallyBrokenScansGiveAnErrorAndNoPoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    RangeScan ranges;
    ScanError expected;
  };
  const std::vector<Case> cases = {
      {makeRanges({}, 0.0, 0.1), ScanError::kNoBeams},
      {makeRanges({1.0f, 1.0f}, 0.0, 0.0), ScanError::kBadAngles},
      {makeRanges({1.0f, 1.0f}, 0.0, nan), ScanError::kBadAngles},
      {makeRanges({1.0f, 1.0f}, 0.0, inf), ScanError::kBadAngles},
      {makeRanges({1.0f, 1.0f}, nan, 0.1), ScanError::kBadAngles},
      {makeRanges({1.0f, 1.0f}, -inf, 0.1), ScanError::kBadAngles},
      {makeRanges({1.0f, 1.0f}, 0.0, 0.1, 5.0, 1.0), ScanError::kBadRangeLimits},
      {makeRanges({1.0f, 1.0f}, 0.0, 0.1, nan, 10.0), ScanError::kBadRangeLimits},
      {makeRanges({1.0f, 1.0f}, 0.0, 0.1, 0.1, nan), ScanError::kBadRangeLimits},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    ScanError error = ScanError::kNone;
    const Scan scan = hglasm::scanFromRanges(cases[i].ranges, {}, &error);
    EXPECT_EQ(error, cases[i].expected) << "case " << i << ": " << hglasm::toString(error);
    EXPECT_TRUE(scan.empty()) << "case " << i;
    EXPECT_TRUE(scan.beam_index.empty()) << "case " << i;
    // Without an error pointer it must not crash either.
    EXPECT_TRUE(hglasm::scanFromRanges(cases[i].ranges).empty()) << "case " << i;
  }
}

TEST(ScanFromRanges, AllInvalidIsEmptyButNotAnError) {
  ScanError error = ScanError::kNoBeams;
  const Scan scan = hglasm::scanFromRanges(makeRanges({kNaN, kInf, 0.0f, 50.0f}, 0.0, 0.1), {}, &error);
  EXPECT_EQ(error, ScanError::kNone);
  EXPECT_TRUE(scan.empty());
  EXPECT_EQ(scan.beam_count, 4);
  EXPECT_EQ(scan.invalid_count, 4);
}

TEST(ScanFromRanges, ErrorStringsAreDistinct) {
  std::set<std::string> names;
  for (ScanError e :
       {ScanError::kNone, ScanError::kNoBeams, ScanError::kBadAngles, ScanError::kBadRangeLimits}) {
    ASSERT_NE(hglasm::toString(e), nullptr);
    EXPECT_GT(std::strlen(hglasm::toString(e)), 0u);
    names.insert(hglasm::toString(e));
  }
  EXPECT_EQ(names.size(), 4u);
}

TEST(SelectBeams, SplitsByOriginalBeamParity) {
  std::vector<float> ranges = {1.0f, 1.0f, kNaN, 1.0f, 1.0f, 1.0f};
  const Scan scan = hglasm::scanFromRanges(makeRanges(ranges, 0.0, 0.1));
  const Scan even = hglasm::selectBeams(scan, 0);
  const Scan odd = hglasm::selectBeams(scan, 1);
  EXPECT_EQ(even.beam_index, (std::vector<int>{0, 4}));
  EXPECT_EQ(odd.beam_index, (std::vector<int>{1, 3, 5}));
  ASSERT_EQ(odd.size(), 3u);
  EXPECT_EQ(odd.points[1], scan.points[2]);  // beam 3 is the third valid point
  EXPECT_EQ(even.size() + odd.size(), scan.size());
  EXPECT_TRUE(hglasm::selectBeams(Scan(), 0).empty());
}

TEST(TransformScan, MovesPointsKeepsIndices) {
  const Scan scan = hglasm::scanFromRanges(makeRanges({1.0f, 2.0f}, 0.0, kPi / 2.0));
  const Scan moved = hglasm::transformScan(scan, hglasm::Pose2D(1.0, -1.0, kPi / 2.0));
  ASSERT_EQ(moved.size(), 2u);
  expectPoint(moved.points[0], 1.0, 0.0);
  expectPoint(moved.points[1], -1.0, -1.0);
  EXPECT_EQ(moved.beam_index, scan.beam_index);
  EXPECT_EQ(moved.beam_count, scan.beam_count);
}

TEST(ScanFromRanges, BeamTimesComeFromTheScanOrElseTheSweepTime) {
  RangeScan ranges = makeRanges({1.0f, 1.0f, 1.0f, 1.0f, 1.0f}, 0.0, 0.1);
  EXPECT_EQ(hglasm::scanFromRanges(ranges).time_increment, 0.0);  // nothing known: no beam times
  ScanConversionOptions options;
  options.sweep_time = 0.02;
  EXPECT_DOUBLE_EQ(hglasm::scanFromRanges(ranges, options).time_increment, 0.005);  // 4 intervals
  ranges.time_increment = 1e-4;  // the driver's own figure wins
  EXPECT_EQ(hglasm::scanFromRanges(ranges, options).time_increment, 1e-4);
  options.beam_step = 2;  // decimation keeps the original beam indices, so the increment is per beam
  EXPECT_EQ(hglasm::scanFromRanges(ranges, options).time_increment, 1e-4);
  for (double broken : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    ranges.time_increment = broken;
    EXPECT_DOUBLE_EQ(hglasm::scanFromRanges(ranges, options).time_increment, 0.005) << broken;
    EXPECT_EQ(hglasm::scanFromRanges(ranges).time_increment, 0.0) << broken;
  }
  ranges.time_increment = 0.5;  // a 2 s sweep: a driver's mistake, not a 2D laser
  EXPECT_DOUBLE_EQ(hglasm::scanFromRanges(ranges, options).time_increment, 0.005);
  const Scan scan = hglasm::scanFromRanges(ranges, options);
  EXPECT_EQ(hglasm::selectBeams(scan, 1).time_increment, scan.time_increment);
}

TEST(DeskewScan, MovesEachPointToTheStamp) {
  Scan scan;  // three beams that all see a point 1 m ahead
  scan.points.assign(3, Eigen::Vector2d(1.0, 0.0));
  scan.beam_index = {0, 1, 2};
  scan.beam_count = 3;
  scan.time_increment = 0.01;
  // Beam 2 is measured 0.02 s after the stamp: the sensor has moved 0.02 m along x and turned pi/100.
  const Scan deskewed = hglasm::deskewScan(scan, Eigen::Vector3d(1.0, 0.0, kPi / 2.0));
  ASSERT_EQ(deskewed.size(), 3u);
  expectPoint(deskewed.points[0], 1.0, 0.0);
  expectPoint(deskewed.points[1], 0.01 + std::cos(kPi / 200.0), std::sin(kPi / 200.0));
  expectPoint(deskewed.points[2], 0.02 + std::cos(kPi / 100.0), std::sin(kPi / 100.0));
  EXPECT_EQ(deskewed.beam_index, scan.beam_index);
}

TEST(DeskewScan, StraightensAWallSweptWhileDriving) {
  // Driving at 2 m/s towards a wall 3 m ahead; a 100 ms sweep sees its right end from 20 cm farther away
  // than its left end, so the wall looks turned by about 4 degrees.
  const int beams = 61;
  const double sweep = 0.1, speed = 2.0;
  RangeScan ranges = makeRanges(std::vector<float>(beams), -kPi / 6.0, (kPi / 3.0) / (beams - 1), 0.1, 20.0);
  std::vector<double> exact(beams);
  for (int i = 0; i < beams; ++i) {
    const double when = i * sweep / (beams - 1);
    const double angle = ranges.angle_min + i * ranges.angle_increment;
    exact[i] = (3.0 - speed * when) / std::cos(angle);
    ranges.ranges[i] = static_cast<float>(exact[i]);
  }
  ranges.time_increment = sweep / (beams - 1);
  const Scan skewed = hglasm::scanFromRanges(ranges);
  ASSERT_EQ(skewed.size(), static_cast<std::size_t>(beams));
  EXPECT_GT(skewed.points.front().x() - skewed.points.back().x(), 0.19);
  const Scan deskewed = hglasm::deskewScan(skewed, Eigen::Vector3d(speed, 0.0, 0.0));
  for (const auto& point : deskewed.points) EXPECT_NEAR(point.x(), 3.0, 1e-5);  // float ranges
  // Not moving, or beam times unknown: nothing changes.
  EXPECT_EQ(hglasm::deskewScan(skewed, Eigen::Vector3d::Zero()).points, skewed.points);
  Scan untimed = skewed;
  untimed.time_increment = 0.0;
  EXPECT_EQ(hglasm::deskewScan(untimed, Eigen::Vector3d(speed, 0.0, 1.0)).points, skewed.points);
  untimed.time_increment = std::numeric_limits<double>::quiet_NaN();  // never NaN points
  EXPECT_EQ(hglasm::deskewScan(untimed, Eigen::Vector3d(speed, 0.0, 1.0)).points, skewed.points);
}

}  // namespace

// ------------------------------------------------------------------ surfaces: which neighbours are joined

namespace {

/// A straight wall seen from `origin` at `incidence` (angle between beam and wall normal at the middle
/// beam), `range` away along the middle beam, sampled every `step` radians: consecutive points in beam order.
std::vector<Eigen::Vector2d> obliqueWall(double range, double incidence, double step, int beams) {
  // Wall through (range, 0) with normal at angle `incidence` from the x axis.
  const Eigen::Vector2d point(range, 0.0), normal(std::cos(incidence), std::sin(incidence));
  std::vector<Eigen::Vector2d> points;
  for (int k = -beams / 2; k <= beams / 2; ++k) {
    const Eigen::Vector2d direction(std::cos(k * step), std::sin(k * step));
    points.push_back(direction * (normal.dot(point) / normal.dot(direction)));
  }
  return points;
}

}  // namespace

TEST(ReferencePoints, AppendRecordsEachScansOrigin) {
  hglasm::ReferencePoints reference;
  reference.append({Eigen::Vector2d(1.0, 0.0)}, hglasm::Pose2D(2.0, 3.0, 0.5));
  reference.append({}, hglasm::Pose2D(9.0, 9.0, 0.0));  // empty: no scan
  reference.append({Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(2.0, 0.0)}, hglasm::Pose2D(-1.0, 0.0, 0.0));
  ASSERT_EQ(reference.scan_origins.size(), 2u);
  EXPECT_EQ(reference.scanOrigin(0), Eigen::Vector2d(2.0, 3.0));
  EXPECT_EQ(reference.scanOrigin(1), Eigen::Vector2d(-1.0, 0.0));
  EXPECT_EQ(reference.scanEnd(0), 1u);
  EXPECT_EQ(reference.scanEnd(1), 3u);
  reference.clear();
  EXPECT_TRUE(reference.scan_origins.empty());
}

TEST(AngularStep, IsTheBeamSpacingSeenFromTheScansOriginDespiteMissingBeams) {
  const double step = hglasm_test::deg(0.5);
  std::vector<Eigen::Vector2d> points = obliqueWall(4.0, 0.3, step, 60);
  points.erase(points.begin() + 10, points.begin() + 14);  // a gap of missing beams
  points[30] = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  hglasm::ReferencePoints reference;
  const hglasm::Pose2D origin(5.0, -2.0, 1.0);
  reference.append(points, origin);  // in another frame: seen from its own origin the spacing is the same
  EXPECT_NEAR(hglasm::angularStep(reference, 0), step, 1e-9);
  EXPECT_EQ(hglasm::angularStep(reference, 1), 0.0) << "no such scan";
}

TEST(JoinSurfaces, FollowTheLasersResolutionUpToTheMaximumIncidence) {
  // 1 degree beams at 10 m: consecutive points of a wall are about 0.17 m / cos(incidence) apart.
  const double step = hglasm_test::deg(1.0);
  hglasm::SurfaceOptions options;  // 0.30 m, 80 degrees
  for (double incidence_deg : {0.0, 60.0, 75.0, 84.0}) {
    SCOPED_TRACE(incidence_deg);
    hglasm::ReferencePoints reference;
    reference.append(obliqueWall(10.0, hglasm_test::deg(incidence_deg), step, 4));
    const std::vector<std::uint8_t> joins = hglasm::joinSurfaces(reference, options);
    ASSERT_EQ(joins.size(), 5u);
    EXPECT_EQ(joins[4], 0) << "the last point has no next";
    // A gap of 0.17 / cos(i) m: within 0.30 m below 55 deg, within 0.30 + 10 * step / cos(80) ~ 1.3 m
    // below 80 deg, beyond it at 84 deg.
    const int expected = incidence_deg < 80.0 ? 1 : 0;
    for (int i = 0; i < 4; ++i) EXPECT_EQ(joins[i], expected) << i;
    // The gap alone (max_incidence 0): only what is within 0.30 m.
    hglasm::SurfaceOptions gap_only = options;
    gap_only.max_incidence = 0.0;
    const std::vector<std::uint8_t> by_gap = hglasm::joinSurfaces(reference, gap_only);
    for (int i = 0; i < 4; ++i) {
      const double gap = (reference.points[i + 1] - reference.points[i]).norm();
      EXPECT_EQ(by_gap[i], gap < 0.30 ? 1 : 0) << i << " gap " << gap;
    }
  }
}

TEST(JoinSurfaces, NeverAcrossScansMissingBeamsOrWithMaxGapZero) {
  hglasm::ReferencePoints reference;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  reference.append({Eigen::Vector2d(2.0, 0.0), Eigen::Vector2d(2.0, 0.05), Eigen::Vector2d(nan, nan),
                    Eigen::Vector2d(2.0, 0.15)});
  reference.append({Eigen::Vector2d(2.0, 0.2), Eigen::Vector2d(2.0, 0.25)});
  EXPECT_EQ(hglasm::joinSurfaces(reference, hglasm::SurfaceOptions()),
            (std::vector<std::uint8_t>{1, 0, 0, 0, 1, 0}));
  hglasm::SurfaceOptions off;
  off.max_gap = 0.0;
  EXPECT_EQ(hglasm::joinSurfaces(reference, off), std::vector<std::uint8_t>(6, 0));
}

TEST(ScanSweepTime, OwnTimingFirstThenTheConfiguredSweepElseUnknown) {
  hglasm::ScanConversionOptions options;
  EXPECT_DOUBLE_EQ(hglasm::scanSweepTime(1e-4, 1001, options), 0.1);
  EXPECT_DOUBLE_EQ(hglasm::scanSweepTime(-1e-4, 1001, options), -0.1) << "signed like time_increment";
  EXPECT_EQ(hglasm::scanSweepTime(0.0, 1001, options), 0.0) << "not known";
  EXPECT_EQ(hglasm::scanSweepTime(0.01, 1001, options), 0.0) << "10 s: a driver's mistake";
  options.sweep_time = 0.05;
  EXPECT_DOUBLE_EQ(hglasm::scanSweepTime(0.0, 1001, options), 0.05);
  EXPECT_DOUBLE_EQ(hglasm::scanSweepTime(std::nan(""), 1001, options), 0.05);
  EXPECT_DOUBLE_EQ(hglasm::scanSweepTime(1e-4, 1001, options), 0.1) << "the scan's own timing wins";
  EXPECT_EQ(hglasm::scanSweepTime(1e-4, 1, options), 0.0) << "one beam has no sweep";
}

TEST(DeskewScan, APerBeamMotionMovesEachPointByTheSensorPoseAtItsTime) {
  Scan scan;
  scan.beam_count = 3;
  scan.time_increment = 0.1;
  scan.points = {{1.0, 0.0}, {1.0, 0.0}, {1.0, 0.0}};
  scan.beam_index = {0, 1, 2};
  // The sensor turns 1 rad/s for 0.1 s, then stands: beam 2 is seen as beam 1.
  const Scan out =
      hglasm::deskewScan(scan, [](double t) { return hglasm::Pose2D(0.0, 0.0, std::min(t, 0.1)); });
  expectPoint(out.points[0], 1.0, 0.0);
  expectPoint(out.points[1], std::cos(0.1), std::sin(0.1));
  expectPoint(out.points[2], std::cos(0.1), std::sin(0.1));
  scan.time_increment = 0.0;
  const Scan unchanged = hglasm::deskewScan(scan, [](double) { return hglasm::Pose2D(1.0, 0.0, 0.0); });
  expectPoint(unchanged.points[2], 1.0, 0.0);  // beam times not known
}
