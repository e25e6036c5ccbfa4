// GLASM lookup tables: graded values (normal in the distance to the nearest reference point), cut-off,
// another stamp given as a kernel, sparse memory, and fitness.
#include "hglasm_odometry/core/lookup_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "test_util.h"

namespace {

using hglasm::LookupTable;
using hglasm::LookupTableOptions;
using Points = std::vector<Eigen::Vector2d>;

constexpr double kCell = 0.02;
constexpr double kSigma = 0.10;
constexpr double kCutoff = 0.30;

/// The papers' point-only table: the distance is to the nearest reference point (no joining segments, no
/// footprints).
LookupTableOptions gradedOptions() {
  LookupTableOptions options;
  options.cell_size = kCell;
  options.sigma = kSigma;
  options.cutoff = kCutoff;
  options.segment_max_gap = 0.0;
  options.isolated_footprint = 0.0;
  return options;
}

double normal255(double distance) { return 255.0 * std::exp(-distance * distance / (2.0 * kSigma * kSigma)); }

// A reference point in the middle of a cell (away from cell borders for any rounding convention).
const Eigen::Vector2d kCentre((37 + 0.5) * kCell, (-11 + 0.5) * kCell);

std::vector<Eigen::Vector2d> linePoints(double length, double spacing) {
  std::vector<Eigen::Vector2d> points;
  for (double x = 0.0; x <= length + 1e-9; x += spacing) points.emplace_back(x, 0.37 * x + 1.0);
  return points;
}

TEST(LookupTable, EmptyBeforeBuildAndForEmptyReference) {
  LookupTable table(gradedOptions());
  EXPECT_TRUE(table.empty());
  EXPECT_EQ(table.valueAt(Eigen::Vector2d::Zero()), 0);
  EXPECT_EQ(table.fitness(Points{Eigen::Vector2d::Zero()}, hglasm::Pose2D()), 0u);
  table.build(std::vector<Eigen::Vector2d>{});
  EXPECT_TRUE(table.empty());
  EXPECT_EQ(table.tileCount(), 0u);
  EXPECT_EQ(table.fitness(Points{Eigen::Vector2d::Zero()}, hglasm::Pose2D()), 0u);
}

TEST(LookupTable, GradedValueIs255AtAReferencePoint) {
  LookupTable table(gradedOptions());
  const std::vector<Eigen::Vector2d> reference = {kCentre, {1.234, -5.678}, {-0.001, 0.001}, {0.0, 0.0}};
  table.build(reference);
  EXPECT_FALSE(table.empty());
  EXPECT_EQ(table.maxCellValue(), 255u);
  for (const auto& p : reference) EXPECT_EQ(table.valueAt(p), 255) << p.transpose();
}

TEST(LookupTable, GradedValueDecaysLikeTheNormalOfTheDistance) {
  LookupTable table(gradedOptions());
  table.build({kCentre});
  int previous = 256;
  for (int k = 0; k <= 15; ++k) {  // 0 .. 0.30 m along +x, -y and the diagonal (3, 4) * k / 5
    const double d = k * kCell;
    const int along_x = table.valueAt(kCentre + Eigen::Vector2d(d, 0.0));
    const int along_minus_y = table.valueAt(kCentre + Eigen::Vector2d(0.0, -d));
    EXPECT_NEAR(along_x, normal255(d), 1.0) << "d = " << d;
    EXPECT_NEAR(along_minus_y, normal255(d), 1.0) << "d = " << d;
    EXPECT_LE(along_x, previous) << "not monotonic at d = " << d;
    previous = along_x;
  }
  // One sigma away on a diagonal: 255 * exp(-1/2) = 155.
  EXPECT_NEAR(table.valueAt(kCentre + Eigen::Vector2d(3 * kCell, 4 * kCell)), normal255(kSigma), 1.0);
  EXPECT_NEAR(table.valueAt(kCentre + Eigen::Vector2d(-6 * kCell, -8 * kCell)), normal255(2 * kSigma), 1.0);
}

TEST(LookupTable, GradedValueIsZeroBeyondTheCutoff) {
  LookupTable table(gradedOptions());
  table.build({kCentre});
  EXPECT_GT(table.valueAt(kCentre + Eigen::Vector2d(kCutoff - kCell, 0.0)), 0);
  EXPECT_EQ(table.valueAt(kCentre + Eigen::Vector2d(kCutoff + kCell, 0.0)), 0);
  EXPECT_EQ(table.valueAt(kCentre + Eigen::Vector2d(0.0, -(kCutoff + 2 * kCell))), 0);
  // The corner of the stamp's square is outside the cut-off circle.
  EXPECT_EQ(table.valueAt(kCentre + Eigen::Vector2d(14 * kCell, 14 * kCell)), 0);
  EXPECT_EQ(table.valueAt(kCentre + Eigen::Vector2d(5.0, 5.0)), 0);
  EXPECT_EQ(table.valueAt(Eigen::Vector2d(-1e6, 1e6)), 0);
  EXPECT_EQ(table.valueAt(Eigen::Vector2d(std::nan(""), 0.0)), 0);
  EXPECT_EQ(table.valueAt(Eigen::Vector2d(std::numeric_limits<double>::infinity(), 0.0)), 0);
}

TEST(LookupTable, CellsHoldTheLikelihoodOfTheNearestPointNotASum) {
  LookupTable table(gradedOptions());
  const Eigen::Vector2d other = kCentre + Eigen::Vector2d(10 * kCell, 0.0);  // 0.2 m apart
  table.build({kCentre, other});
  EXPECT_EQ(table.valueAt(kCentre), 255);
  EXPECT_EQ(table.valueAt(other), 255);
  // Halfway: 0.1 m from both, one sigma: 155, not 2 * 155 (saturated) or a sum of tails.
  EXPECT_NEAR(table.valueAt(kCentre + Eigen::Vector2d(5 * kCell, 0.0)), normal255(kSigma), 1.0);
}

TEST(LookupTable, SegmentsJoinCloseConsecutivePointsOnly) {
  LookupTableOptions options = gradedOptions();
  options.segment_max_gap = 0.30;
  options.segment_max_incidence = 0.0;  // the gap alone
  LookupTable table(options);
  // Beam order: a and b are 0.24 m apart (joined); b and c are 1.0 m apart (not joined).
  const Eigen::Vector2d a = kCentre, b = kCentre + Eigen::Vector2d(12 * kCell, 0.0),
                        c = b + Eigen::Vector2d(0.0, 50 * kCell);
  table.build({a, b, c});
  EXPECT_EQ(table.valueAt(a), 255);
  EXPECT_EQ(table.valueAt(b), 255);
  EXPECT_EQ(table.valueAt(c), 255);
  for (int k = 1; k < 12; ++k) {  // on the surface between a and b: as good as a measured point
    EXPECT_GE(table.valueAt(a + Eigen::Vector2d(k * kCell, 0.0)), 250) << k;
  }
  // Off the surface it decays with the distance to the segment.
  EXPECT_NEAR(table.valueAt(a + Eigen::Vector2d(6 * kCell, 5 * kCell)), normal255(kSigma), 3.0);
  // Halfway between b and c (0.5 m from both, no segment): nothing.
  EXPECT_EQ(table.valueAt(b + Eigen::Vector2d(0.0, 25 * kCell)), 0);
  // Only consecutive points are joined: in the order a, c, b, a and b are no longer neighbours.
  LookupTable reordered(options);
  reordered.build({a, c, b});
  EXPECT_LT(reordered.valueAt(a + Eigen::Vector2d(6 * kCell, 0.0)), 250);
}

/// A plus of 7s, two cells long each way (a kernel the graded one is not).
hglasm::TableKernel plusKernel(const LookupTableOptions&) {
  hglasm::TableKernel kernel;
  kernel.radius = 2;
  kernel.values.assign(25, 0);
  for (int i = 0; i < 5; ++i) kernel.values[2 * 5 + i] = kernel.values[i * 5 + 2] = 7;
  return kernel;
}

hglasm::TableKernel wrongSizeKernel(const LookupTableOptions&) {
  hglasm::TableKernel kernel;
  kernel.radius = 2;
  kernel.values.assign(24, 9);
  return kernel;
}

TEST(LookupTable, AKernelFunctionReplacesTheGradedStamp) {
  LookupTable plus(gradedOptions(), plusKernel);
  plus.build({kCentre});
  EXPECT_EQ(plus.maxCellValue(), 7u) << "the kernel's largest value";
  for (int d = -2; d <= 2; ++d) {
    EXPECT_EQ(plus.valueAt(kCentre + kCell * Eigen::Vector2d(d, 0.0)), 7) << d;
    EXPECT_EQ(plus.valueAt(kCentre + kCell * Eigen::Vector2d(0.0, d)), 7) << d;
  }
  EXPECT_EQ(plus.valueAt(kCentre + kCell * Eigen::Vector2d(1.0, 1.0)), 0);
  EXPECT_EQ(plus.valueAt(kCentre + kCell * Eigen::Vector2d(3.0, 0.0)), 0);
  EXPECT_EQ(plus.fitness(Points{kCentre}, hglasm::Pose2D()), 7u);
  // A kernel of the wrong size is not trusted: the graded stamp instead.
  LookupTable fallback(gradedOptions(), wrongSizeKernel);
  fallback.build({kCentre});
  LookupTable graded(gradedOptions());
  graded.build({kCentre});
  EXPECT_EQ(fallback.maxCellValue(), 255u);
  for (int d = 0; d <= 16; ++d) {
    const Eigen::Vector2d at = kCentre + kCell * Eigen::Vector2d(d, 0.5 * d);
    EXPECT_EQ(fallback.valueAt(at), graded.valueAt(at)) << d;
  }
}

TEST(LookupTable, FitnessOfTheReferenceItselfIsTheMaximum) {
  const auto world = hglasm_test::room();
  const auto scan =
      hglasm_test::simulateScan(world, hglasm::Pose2D(0.1, -0.2, 0.3), hglasm_test::halfCircleLaser());
  ASSERT_GT(scan.size(), 300u);
  LookupTable graded(gradedOptions());
  graded.build(scan.points);
  EXPECT_EQ(graded.fitness(scan.points, hglasm::Pose2D()), 255u * scan.size());
  // A displaced copy fits less.
  EXPECT_LT(graded.fitness(scan.points, hglasm::Pose2D(0.05, 0.0, 0.0)), 255u * scan.size());
  EXPECT_LT(graded.fitness(scan.points, hglasm::Pose2D(0.0, 0.0, 0.05)), 255u * scan.size());
  // Far away nothing fits.
  EXPECT_EQ(graded.fitness(scan.points, hglasm::Pose2D(100.0, 0.0, 0.0)), 0u);
}

TEST(LookupTable, FitnessIsTheSumOfCellValuesOfTheMovedPoints) {
  const auto world = hglasm_test::room();
  const auto reference = hglasm_test::simulateScan(world, hglasm::Pose2D(), hglasm_test::halfCircleLaser());
  const auto other =
      hglasm_test::simulateScan(world, hglasm::Pose2D(0.2, 0.1, 0.1), hglasm_test::halfCircleLaser());
  LookupTable table(gradedOptions());
  table.build(reference.points);
  for (const hglasm::Pose2D& pose : {hglasm::Pose2D(), hglasm::Pose2D(0.2, 0.1, 0.1),
                                     hglasm::Pose2D(0.21, 0.08, 0.12), hglasm::Pose2D(-1, 2, 3)}) {
    std::uint64_t sum = 0;
    for (const auto& p : hglasm_test::movePoints(other.points, pose)) sum += table.valueAt(p);
    // Rounding of a moved point exactly onto a cell border may differ by one cell for a few points.
    EXPECT_NEAR(static_cast<double>(table.fitness(other.points, pose)), static_cast<double>(sum),
                0.01 * sum + 1.0);
  }
  // The true pose of the other scan fits far better than a wrong one.
  EXPECT_GT(table.fitness(other.points, hglasm::Pose2D(0.2, 0.1, 0.1)),
            2 * table.fitness(other.points, hglasm::Pose2D()));
}

TEST(LookupTable, PreparedPointsGiveTheSameFitness) {
  const auto world = hglasm_test::room();
  const auto reference = hglasm_test::simulateScan(world, hglasm::Pose2D(), hglasm_test::halfCircleLaser());
  const auto other =
      hglasm_test::simulateScan(world, hglasm::Pose2D(0.2, 0.1, 0.1), hglasm_test::halfCircleLaser());
  LookupTable table(gradedOptions());
  table.build(reference.points);
  hglasm::FitnessPoints prepared;
  prepared.assign(other.points);
  ASSERT_EQ(prepared.size(), other.size());
  for (const hglasm::Pose2D& pose :
       {hglasm::Pose2D(), hglasm::Pose2D(0.2, 0.1, 0.1), hglasm::Pose2D(-1, 2, 3)}) {
    const double exact = table.fitness(other.points, pose);
    // Single precision may move a point on a cell border into the neighbouring cell.
    EXPECT_NEAR(static_cast<double>(table.fitness(prepared, pose)), exact, 0.01 * exact + 1.0);
  }
  // The reference itself: every point on its own cell. (Walls at whole-cell coordinates, like y = -4 m
  // seen from the origin, put points within rounding of a cell border; single precision may then pick the
  // neighbouring cell, 250 instead of 255, for some of them: within 1 %.)
  prepared.assign(reference.points);
  EXPECT_GE(table.fitness(prepared, hglasm::Pose2D()), 0.99 * 255.0 * reference.size());
  EXPECT_LE(table.fitness(prepared, hglasm::Pose2D()), 255u * reference.size());
}

TEST(LookupTable, NonFinitePointsAreIgnored) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  LookupTable table(gradedOptions());
  table.build({kCentre, {nan, 0.0}, {0.0, inf}, {-inf, nan}});
  EXPECT_EQ(table.valueAt(kCentre), 255);
  EXPECT_LE(table.tileCount(), 4u);
  EXPECT_EQ(table.fitness(Points{kCentre, {nan, nan}, {inf, 0.0}}, hglasm::Pose2D()), 255u);
  EXPECT_EQ(table.fitness(Points{kCentre}, hglasm::Pose2D(nan, 0.0, 0.0)), 0u);
  LookupTable only_bad(gradedOptions());
  only_bad.build({{nan, nan}});
  EXPECT_TRUE(only_bad.empty());
}

TEST(LookupTable, MemoryIsProportionalToTheCoveredArea) {
  LookupTable short_line(gradedOptions());
  short_line.build(linePoints(10.0, 0.05));
  LookupTable long_line(gradedOptions());
  long_line.build(linePoints(20.0, 0.05));
  const double ratio =
      static_cast<double>(long_line.tileCount()) / static_cast<double>(short_line.tileCount());
  EXPECT_GT(ratio, 1.6);
  EXPECT_LT(ratio, 2.4);
  const double memory_ratio =
      static_cast<double>(long_line.memoryBytes()) / static_cast<double>(short_line.memoryBytes());
  EXPECT_LT(memory_ratio, 3.0);
  // A diagonal wall 28 m long covers a strip, not the 20 m x 20 m bounding box of a dense grid.
  std::vector<Eigen::Vector2d> diagonal;
  for (double t = 0.0; t <= 20.0; t += 0.05) diagonal.emplace_back(t, t);
  LookupTable diagonal_table(gradedOptions());
  diagonal_table.build(diagonal);
  const double dense_bytes = (20.0 / kCell) * (20.0 / kCell);
  EXPECT_LT(static_cast<double>(diagonal_table.memoryBytes()), 0.25 * dense_bytes);
}

TEST(LookupTable, FarApartPointsDoNotAllocateTheSpaceBetween) {
  LookupTable table(gradedOptions());
  table.build({{0.0, 0.0}, {100.0, 100.0}});
  EXPECT_LE(table.tileCount(), 8u);                              // at most 4 tiles around each point
  const double dense_bytes = (100.0 / kCell) * (100.0 / kCell);  // 25 MB
  EXPECT_LT(static_cast<double>(table.memoryBytes()), 0.01 * dense_bytes);
  EXPECT_EQ(table.valueAt({100.0, 100.0}), 255);
  EXPECT_EQ(table.valueAt({50.0, 50.0}), 0);
}

TEST(LookupTable, WildButFinitePointsDoNotExhaustMemory) {
  LookupTable table(gradedOptions());
  table.build({{0.0, 0.0}, {1e7, -1e7}, {3e38, 3e38}, {-1e300, 0.0}});
  EXPECT_EQ(table.valueAt({0.0, 0.0}), 255);
  EXPECT_LT(table.memoryBytes(), std::size_t{64} << 20);
  EXPECT_EQ(table.fitness(Points{{1e300, -1e300}, {0.0, 0.0}}, hglasm::Pose2D()), 255u);
}

TEST(LookupTable, RebuildReplacesTheOldReference) {
  LookupTable table(gradedOptions());
  table.build({{0.0, 0.0}});
  EXPECT_EQ(table.valueAt({0.0, 0.0}), 255);
  table.build({{10.0, -3.0}});
  EXPECT_EQ(table.valueAt({0.0, 0.0}), 0);
  EXPECT_EQ(table.valueAt({10.0, -3.0}), 255);
  table.build(std::vector<Eigen::Vector2d>{});
  EXPECT_TRUE(table.empty());
  EXPECT_EQ(table.valueAt({10.0, -3.0}), 0);
}

TEST(LookupTable, InsertingScanByScanGivesTheTableBuiltAtOnce) {
  // Three scans far apart and overlapping, in an order that grows the tile grid to every side: inserted
  // one by one, the table is cell for cell the one built from all three.
  LookupTableOptions options;  // joined surfaces and footprints included
  hglasm::ReferencePoints all, first, second, third;
  const auto scan = [](double x0, double y0, double heading) {
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i < 60; ++i) {
      const double angle = heading - 0.8 + 0.027 * i;
      const double range = 2.0 + 0.3 * std::sin(0.4 * i);
      points.emplace_back(x0 + range * std::cos(angle), y0 + range * std::sin(angle));
    }
    return points;
  };
  first.append(scan(5.0, 5.0, 0.3));
  second.append(scan(-4.0, -6.0, 2.0));
  third.append(scan(4.5, 4.0, -1.0));
  for (const auto* part : {&first, &second, &third}) all.append(part->points);
  LookupTable built(options), inserted(options);
  built.build(all);
  for (const auto* part : {&first, &second, &third}) inserted.insert(*part);
  int compared = 0;
  for (double x = -9.0; x <= 10.0; x += 0.013) {
    for (double y = -11.0; y <= 10.0; y += 0.017) {
      ASSERT_EQ(inserted.valueAt({x, y}), built.valueAt({x, y})) << x << ", " << y;
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000000);
  EXPECT_EQ(inserted.tileCount(), built.tileCount());
  inserted.clear();
  EXPECT_TRUE(inserted.empty());
  EXPECT_EQ(inserted.valueAt({5.0, 5.0}), 0);
}

TEST(LookupTable, AQueryFrameMovesEveryQueryIntoTheTable) {
  // A table in a fixed frame asked in another: the query frame's pose in the table's frame is applied to
  // every pose and point handed in.
  LookupTable table(gradedOptions());
  table.build({kCentre});
  const hglasm::Pose2D query_in_table(1.0, -2.0, 0.7);
  table.setQueryFrame(query_in_table);
  const Eigen::Vector2d in_query = query_in_table.inverse() * kCentre;
  EXPECT_EQ(table.valueAt(in_query), 255);
  EXPECT_EQ(table.valueAt(kCentre), 0);
  hglasm::FitnessPoints point;
  point.assign({Eigen::Vector2d::Zero()});
  const hglasm::Pose2D at_centre(in_query.x(), in_query.y(), 0.3);
  EXPECT_EQ(table.fitness(point, at_centre), 255u);
  EXPECT_EQ(table.beamsThroughSurfaces({Eigen::Vector2d(1.0, 0.0)},
                                       hglasm::Pose2D(in_query.x() - 0.5, in_query.y(), 0.0), 0.05),
            1);
}

TEST(LookupTable, OtherCellSizesAndSigmas) {
  LookupTableOptions options = gradedOptions();
  options.cell_size = 0.01;
  options.sigma = 0.05;
  options.cutoff = 0.15;
  LookupTable table(options);
  const Eigen::Vector2d centre(0.005, 0.005);
  table.build({centre});
  EXPECT_EQ(table.valueAt(centre), 255);
  EXPECT_NEAR(table.valueAt(centre + Eigen::Vector2d(0.05, 0.0)), 255.0 * std::exp(-0.5), 1.0);
  EXPECT_EQ(table.valueAt(centre + Eigen::Vector2d(0.17, 0.0)), 0);
}

}  // namespace

TEST(LookupTable, AnIsolatedPointIsStampedAcrossItsBeamAsWideAsItsAngularStep) {
  // Two isolated points 8 m out, 2 degrees apart as seen from the origin (0.28 m: not joined with the
  // gap alone). Each stands for the surface over its beam's angular cell: +-0.14 m across the beam.
  LookupTableOptions options = gradedOptions();
  options.segment_max_gap = 0.05;
  options.segment_max_incidence = 0.0;
  options.isolated_footprint = 1.0;
  const double step = 2.0 * M_PI / 180.0, range = 8.0;
  const Eigen::Vector2d a(range, 0.0), b(range * std::cos(step), range * std::sin(step));
  LookupTable table(options);
  table.build({a, b});
  options.isolated_footprint = 0.0;
  LookupTable point_only(options);
  point_only.build({a, b});
  const Eigen::Vector2d across(0.0, 1.0), along(1.0, 0.0);  // at a
  const double half_width = 0.5 * range * step;
  for (double offset : {0.0, 0.5 * half_width, 0.95 * half_width}) {
    EXPECT_GE(table.valueAt(a - offset * across), 240) << offset;
    EXPECT_GE(table.valueAt(b - offset * Eigen::Vector2d(-std::sin(step), std::cos(step))), 240) << offset;
  }
  EXPECT_LT(point_only.valueAt(a - 0.95 * half_width * across), 130);
  // Beyond the footprint it decays from its end (2 sigma: 255 exp(-2) = 35); the point alone is past the
  // cutoff there.
  const double beyond = table.valueAt(a - (half_width + 2.0 * kSigma) * across);
  EXPECT_GT(beyond, 15);
  EXPECT_LT(beyond, 60);
  EXPECT_EQ(point_only.valueAt(a - (half_width + 2.0 * kSigma) * across), 0);
  // Along the beam it is still a point.
  EXPECT_LT(table.valueAt(a + 2.0 * kSigma * along), 60);
}

TEST(LookupTable, JoinedPointsGetNoFootprintAndAFewScatteredPointsNoHugeOne) {
  LookupTableOptions options = gradedOptions();
  options.segment_max_gap = 0.30;
  options.isolated_footprint = 1.0;
  // A wall 2 m out, points 2 cm apart: joined, so its end is not stamped further along it.
  std::vector<Eigen::Vector2d> wall;
  for (int k = -20; k <= 20; ++k) wall.emplace_back(2.0, 0.02 * k);
  LookupTable table(options);
  table.build(wall);
  EXPECT_LT(table.valueAt(Eigen::Vector2d(2.0, 0.48)), 220);
  // Three points 90 degrees apart at 100 m: the footprint is capped (0.5 m), not 78 m wide.
  LookupTable scattered(options);
  scattered.build({Eigen::Vector2d(100.0, 0.0), Eigen::Vector2d(0.0, 100.0), Eigen::Vector2d(-100.0, 0.0)});
  EXPECT_GE(scattered.valueAt(Eigen::Vector2d(100.0, 0.45)), 240);
  EXPECT_EQ(scattered.valueAt(Eigen::Vector2d(100.0, 0.5 + kCutoff + 0.05)), 0);
  EXPECT_LT(scattered.memoryBytes(), std::size_t(1) << 20);
}

namespace {

/// A wall of reference points 2 m ahead of the origin, from y = -1 to 1, every centimetre.
Points wallAtTwoMetres() {
  Points wall;
  for (int i = -100; i <= 100; ++i) wall.emplace_back(2.0, 0.01 * i);
  return wall;
}

}  // namespace

TEST(LookupTable, BeamsThroughSurfacesCountsOnlyBeamsThatPassTheWall) {
  LookupTable table(gradedOptions());
  table.build(wallAtTwoMetres());
  const double margin = 3.0 * kSigma;
  // Beyond the wall (through it), in front of it (an occluder), on it, and pointing away from it.
  const Points beams = {{3.0, 0.0}, {4.0, 0.5}, {1.2, 0.0}, {2.0, 0.3}, {-3.0, 0.0}};
  EXPECT_EQ(table.beamsThroughSurfaces(beams, hglasm::Pose2D(), margin), 2);
  // Turned around, every beam points away from the wall but the last, which now passes it.
  EXPECT_EQ(table.beamsThroughSurfaces(beams, hglasm::Pose2D(0.0, 0.0, M_PI), margin), 1);
  // Moved beyond the wall: nothing lies between the sensor and the points ahead.
  EXPECT_EQ(table.beamsThroughSurfaces({{3.0, 0.0}, {4.0, 0.5}}, hglasm::Pose2D(2.5, 0.0, 0.0), margin), 0);
}

TEST(LookupTable, BeamsThroughSurfacesIsZeroForAnEmptyTableOrPose) {
  LookupTable empty(gradedOptions());
  EXPECT_EQ(empty.beamsThroughSurfaces({{3.0, 0.0}}, hglasm::Pose2D(), 0.3), 0);
  LookupTable table(gradedOptions());
  table.build(wallAtTwoMetres());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(table.beamsThroughSurfaces({{3.0, 0.0}}, hglasm::Pose2D(nan, 0.0, 0.0), 0.3), 0);
  EXPECT_EQ(table.beamsThroughSurfaces({{nan, 0.0}}, hglasm::Pose2D(), 0.3), 0);
  // A wild but finite reading (the fuzzer's 1e30 m) is walked only across the table: a count, at once.
  EXPECT_EQ(table.beamsThroughSurfaces({{1e30, 0.0}, {1e12, 1e12}}, hglasm::Pose2D(), 0.3), 1);
  // A beam that never meets the table's extent is not walked at all.
  EXPECT_EQ(table.beamsThroughSurfaces({{0.0, 1e9}}, hglasm::Pose2D(0.0, 50.0, 0.0), 0.3), 0);
}

namespace {

/// Every cell around random points holds the kernel's value at its nearest centre cell (the maximum of
/// the stamps), computed here independently, for kernels narrower than a 16-byte chunk, up to a tile and
/// wider than a tile, wherever the stamps fall against the tiles' edges.
void expectStampsOfRandomPoints(double cell, double cutoff) {
  LookupTableOptions options = gradedOptions();
  options.cell_size = cell;
  options.cutoff = cutoff;
  LookupTable table(options);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.5);
  Points points;
  for (int i = 0; i < 40; ++i) points.emplace_back(coordinate(rng), coordinate(rng));
  table.build(points);
  std::vector<std::pair<long, long>> centres;
  for (const auto& p : points) {
    centres.emplace_back(static_cast<long>(std::floor(p.x() / cell)),
                         static_cast<long>(std::floor(p.y() / cell)));
  }
  const long reach = static_cast<long>(std::ceil(cutoff / cell)) + 2;
  const long low = static_cast<long>(std::floor(-1.0 / cell)) - reach;
  const long high = static_cast<long>(std::floor(1.5 / cell)) + reach;
  for (long y = low; y <= high; y += 3) {
    for (long x = low; x <= high; ++x) {
      long expected = 0;
      for (const auto& centre : centres) {
        const double distance = std::hypot(x - centre.first, y - centre.second) * cell;
        if (distance <= cutoff) expected = std::max(expected, std::lround(normal255(distance)));
      }
      const Eigen::Vector2d at((x + 0.5) * cell, (y + 0.5) * cell);
      ASSERT_EQ(table.valueAt(at), expected) << "cell " << x << " " << y << ", cell size " << cell;
    }
  }
}

TEST(LookupTable, StampsOfAnyWidthHoldTheNearestCentresValue) {
  expectStampsOfRandomPoints(0.04, 0.30);   // 15 columns: one 16-byte chunk per row
  expectStampsOfRandomPoints(0.02, 0.30);   // 31 columns: chunks, within a tile
  expectStampsOfRandomPoints(0.008, 0.30);  // 77 columns: wider than a tile
}

}  // namespace
