// The local map: two overlapping submaps of the last keyframes at their poses, offered in the newest
// keyframe's frame, and their lookup tables grown keyframe by keyframe.
#include "hglasm_odometry/core/local_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_util.h"

namespace {

using hglasm::LocalMap;
using hglasm::LocalMapOptions;
using hglasm::Pose2D;

/// Points of a straight wall x = distance in the laser frame, 1 cm apart, |y| <= half_length.
std::vector<Eigen::Vector2d> wall(double distance, double half_length = 1.0, double spacing = 0.01) {
  std::vector<Eigen::Vector2d> points;
  for (double y = -half_length; y <= half_length + 1e-9; y += spacing) points.emplace_back(distance, y);
  return points;
}

TEST(LocalMap, TwoOverlappingSubmapsHoldTheLastKeyframesInTheNewestFrame) {
  // Three keyframes per submap: a new submap starts when the newer one holds three, and the older one goes
  // then, so the matched submap holds between four and six keyframes once the map is running.
  LocalMapOptions options;
  options.keyframes = 3;
  options.resolution = 0.0;
  LocalMap map(options);
  EXPECT_TRUE(map.empty());
  const std::vector<std::size_t> expected_count = {1, 2, 3, 4, 5, 6, 4, 5, 6, 4};
  for (int k = 0; k < 10; ++k) {
    map.add(Pose2D(1.0 * k, 0.0, 0.1 * k), {Eigen::Vector2d(2.0, 0.0)});
    EXPECT_EQ(map.keyframeCount(), expected_count[k]) << "after keyframe " << k;
  }
  EXPECT_NEAR(map.frame().x, 9.0, 1e-12);
  EXPECT_NEAR(map.frame().theta, 0.9, 1e-12);
  // Oldest first: keyframes 6 to 9, each point 2 m ahead of its keyframe, seen from keyframe 9.
  const hglasm::ReferencePoints& reference = map.reference();
  ASSERT_EQ(reference.size(), 4u);
  EXPECT_EQ(reference.scan_starts, (std::vector<std::size_t>{0, 1, 2, 3}));
  for (int k = 6; k <= 9; ++k) {
    const Eigen::Vector2d expected =
        map.frame().inverse() * (Pose2D(1.0 * k, 0.0, 0.1 * k) * Eigen::Vector2d(2.0, 0.0));
    EXPECT_NEAR((reference.points[k - 6] - expected).norm(), 0.0, 1e-12) << "keyframe " << k;
    const Eigen::Vector2d origin = map.frame().inverse() * Pose2D(1.0 * k, 0.0, 0.1 * k).translation();
    EXPECT_NEAR((reference.scanOrigin(k - 6) - origin).norm(), 0.0, 1e-12) << "keyframe " << k;
  }
  EXPECT_NEAR((reference.points[3] - Eigen::Vector2d(2.0, 0.0)).norm(), 0.0, 1e-12)
      << "the newest keyframe's points are its own";
  map.clear();
  EXPECT_TRUE(map.empty());
  EXPECT_TRUE(map.reference().empty());
}

TEST(LocalMap, ASubmapTooFarFromTheNewestKeyframeLeaves) {
  LocalMapOptions options;
  options.keyframes = 4;
  options.max_distance = 2.5;
  options.resolution = 0.0;
  LocalMap map(options);
  for (int k = 0; k < 6; ++k) map.add(Pose2D(1.0 * k, 0.0, 0.0), wall(3.0));
  // Keyframes 0-3 started the first submap, 4 the second; at keyframe 5 the first starts 5 m away.
  EXPECT_EQ(map.keyframeCount(), 2u) << "the submap of keyframes 4 and 5";
  map.add(Pose2D(6.0, 0.0, 0.0), wall(3.0));
  EXPECT_EQ(map.keyframeCount(), 3u) << "the newer submap goes only once a third would start";
}

TEST(LocalMap, ItsTablesGrowKeyframeByKeyframeAndAnswerInTheNewestFrame) {
  // The submap's table in its first keyframe's frame, grown by inserts, against a table built at once from
  // the reference the map offers in the newest frame: the same values at every probed point.
  LocalMapOptions options;
  options.keyframes = 50;
  hglasm::LookupTableOptions table;
  LocalMap map(options, {table});
  for (int k = 0; k < 8; ++k) {
    map.add(Pose2D(0.4 * k, 0.1 * std::sin(k), 0.05 * k), wall(3.0, 2.0, 0.05));
  }
  hglasm::LookupTable built(table);
  built.build(map.reference());
  ASSERT_FALSE(map.table(0).empty());
  int probed = 0, mismatched = 0;
  for (double x = -1.0; x <= 5.0; x += 0.037) {
    for (double y = -3.0; y <= 3.0; y += 0.041) {
      const int a = map.table(0).valueAt(Eigen::Vector2d(x, y)), b = built.valueAt(Eigen::Vector2d(x, y));
      // Cells of the two tables are rotated against each other: a value may differ by up to about two cells'
      // worth of the kernel's slope (4 cm cells, sigma 10 cm: up to ~60 per cell).
      mismatched += std::abs(a - b) > 130;
      ++probed;
    }
  }
  EXPECT_LT(mismatched, probed / 1000) << mismatched << " of " << probed;
  // A scan on the wall scores the same on both (the fitness is read in the newest keyframe's frame).
  hglasm::FitnessPoints points;
  points.assign(wall(3.0, 2.0, 0.1));
  const double fitness = map.table(0).fitness(points, Pose2D());
  EXPECT_NEAR(fitness / built.fitness(points, Pose2D()), 1.0, 0.05);
  EXPECT_GT(fitness, 0.8 * 255.0 * points.size());
  EXPECT_TRUE(map.table(1).empty()) << "no such table";
}

TEST(LocalMap, OverlappingViewsAddNothingButAKeyframeKeepsAllItsOwnPoints) {
  LocalMapOptions options;
  options.resolution = 0.03;
  LocalMap map(options);
  const std::vector<Eigen::Vector2d> dense = wall(2.0, 1.0, 0.01);  // 1 cm apart: closer than the resolution
  map.add(Pose2D(), dense);
  EXPECT_EQ(map.reference().size(), dense.size()) << "a keyframe is never thinned by its own points";
  map.add(Pose2D(0.0, 0.005, 0.0), dense);  // the same wall, 5 mm to the side
  EXPECT_EQ(map.reference().size(), dense.size()) << "a second look at the same wall adds nothing";
  map.add(Pose2D(0.0, 1.5, 0.0), dense);  // y 0.5 .. 2.5: new wall from 1.03 m on (3 cm past the old end)
  const std::size_t added = map.reference().size() - dense.size();
  EXPECT_GE(added, 147u);
  EXPECT_LE(added, 149u);
  // Oldest first: the overlapped stretch keeps the first keyframe's points.
  EXPECT_NEAR((map.frame().inverse() * Pose2D()).y, -1.5, 1e-12);
  EXPECT_EQ(map.reference().scan_starts.front(), 0u);
  EXPECT_EQ(map.reference().scan_starts.size(), 2u) << "the second keyframe added no point";
}

TEST(LocalMap, AKeptPointKeepsItsNeighbouringBeamsSoItsSurfaceStaysASurface) {
  LocalMapOptions options;
  options.resolution = 0.03;
  LocalMap map(options);
  // The first keyframe sees the wall at y = 0, 0.4, 0.8 and 1.2.
  map.add(Pose2D(), {Eigen::Vector2d(2.0, 0.0), Eigen::Vector2d(2.0, 0.4), Eigen::Vector2d(2.0, 0.8),
                     Eigen::Vector2d(2.0, 1.2)});
  // The second sees it every 0.1 m from y = 0 to 1.6, some beams on an object 0.5 m behind: only
  // y = 0, 0.4, 0.8 and 1.2 are covered, and each stays as the neighbouring beam of a new point (alone,
  // the new points between them would be loose pairs and triples).
  std::vector<Eigen::Vector2d> second;
  for (int k = 0; k <= 16; ++k) second.emplace_back(2.0, 0.1 * k);
  for (int k : {1, 2, 3, 9, 10, 11}) second[k].x() = 2.5;  // 0.5 m behind: not covered either
  map.add(Pose2D(), second);
  const hglasm::ReferencePoints& reference = map.reference();
  ASSERT_EQ(reference.scan_starts.size(), 2u);
  std::vector<double> kept_y;
  for (std::size_t i = reference.scan_starts[1]; i < reference.size(); ++i)
    kept_y.push_back(reference.points[i].y());
  const std::vector<double> expected = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8,
                                        0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6};
  ASSERT_EQ(kept_y.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(kept_y[i], expected[i], 1e-9) << i;
  // A run of covered beams loses its inner points only.
  LocalMap other(options);
  other.add(Pose2D(), wall(2.0, 1.0, 0.1));
  std::vector<Eigen::Vector2d> extended = wall(2.0, 1.0, 0.1);
  extended.emplace_back(2.0, 1.3);  // one new beam past the end: it and its neighbour stay
  other.add(Pose2D(), extended);
  EXPECT_EQ(other.reference().size(), wall(2.0, 1.0, 0.1).size() + 2);
}

TEST(LocalMap, SurfacesAreNeverJoinedAcrossKeyframes) {
  LocalMapOptions options;
  options.resolution = 0.0;
  LocalMap map(options);
  map.add(Pose2D(), {Eigen::Vector2d(2.0, 0.0), Eigen::Vector2d(2.0, 0.1)});
  map.add(Pose2D(0.0, 0.0, 0.0), {Eigen::Vector2d(2.0, 0.15), Eigen::Vector2d(2.0, 0.25)});
  const std::vector<std::uint8_t> same = map.reference().sameScanAsNext();
  EXPECT_EQ(same, (std::vector<std::uint8_t>{1, 0, 1, 0}));
}

TEST(LocalMap, RevisionChangesWithEveryAddAndClearOnly) {
  LocalMap map;
  const auto initial = map.revision();
  map.add(Pose2D(), wall(2.0));
  const auto first = map.revision();
  EXPECT_NE(first, initial);
  EXPECT_EQ(map.revision(), first) << "reading the map changes nothing";
  map.add(Pose2D(0.5, 0.0, 0.0), wall(2.5));
  const auto second = map.revision();
  EXPECT_NE(second, first);
  map.clear();
  EXPECT_NE(map.revision(), second);
}

TEST(LocalMap, WildButFiniteReadingsNeverReachTheGrid) {
  // A reading 1e30 m out (the fuzzer's) is finite but no grid cell: it is neither de-duplicated against nor
  // remembered (the cell index would overflow), and the map stays usable.
  LocalMapOptions options;
  LocalMap map(options, {hglasm::LookupTableOptions()});
  std::vector<Eigen::Vector2d> points = wall(2.0, 1.0, 0.05);
  points.emplace_back(2.1e30, -1.6e26);
  map.add(Pose2D(), points);
  map.add(Pose2D(0.1, 0.0, 0.0), points);
  EXPECT_EQ(map.keyframeCount(), 2u);
  EXPECT_FALSE(map.table(0).empty());
}

TEST(LocalMap, AtLeastOneKeyframe) {
  LocalMapOptions options;
  options.keyframes = 0;
  LocalMap map(options);
  map.add(Pose2D(), wall(2.0));
  EXPECT_EQ(map.keyframeCount(), 1u);
}

}  // namespace

namespace {

TEST(LocalMap, ItsFrameMovesOnlyEveryReframeDistanceAndOtherwiseKeyframesOnlyAddPoints) {
  LocalMapOptions options;
  options.keyframes = 20;
  options.resolution = 0.0;
  options.reframe_distance = 1.0;
  LocalMap map(options);
  LocalMap rebuilt([&] {  // the same map re-expressed at every keyframe
    LocalMapOptions every = options;
    every.reframe_distance = 0.0;
    return every;
  }());
  int reframes = 0;
  for (int k = 0; k < 12; ++k) {
    const Pose2D pose(0.3 * k, 0.05 * k, 0.02 * k);  // 0.3 m apart
    const Pose2D frame_before = map.frame();
    map.add(pose, wall(2.0, 0.5, 0.05));
    rebuilt.add(pose, wall(2.0, 0.5, 0.05));
    EXPECT_EQ(rebuilt.unchangedScans(), 0u);
    const bool moved = map.unchangedScans() == 0;
    reframes += moved;
    if (moved) {
      EXPECT_NEAR((map.frame().translation() - pose.translation()).norm(), 0.0, 1e-12) << "keyframe " << k;
    } else {
      EXPECT_EQ(map.frame().x, frame_before.x);
      EXPECT_EQ(map.unchangedScans() + 1, map.reference().scan_starts.size()) << "one scan added";
      EXPECT_LT((frame_before.translation() - pose.translation()).norm(), options.reframe_distance);
    }
    // Whichever frame it is in, the reference is the same points in the odometry frame.
    ASSERT_EQ(map.reference().size(), rebuilt.reference().size());
    for (std::size_t i = 0; i < map.reference().size(); ++i) {
      const Eigen::Vector2d a = map.frame() * map.reference().points[i];
      const Eigen::Vector2d b = rebuilt.frame() * rebuilt.reference().points[i];
      EXPECT_NEAR((a - b).norm(), 0.0, 1e-9) << "keyframe " << k << ", point " << i;
    }
    EXPECT_EQ(map.reference().scan_steps.size(), map.reference().scan_starts.size());
    EXPECT_NEAR(map.table(0).maxCellValue(), rebuilt.table(0).maxCellValue(), 0);
  }
  // 0.3 m per keyframe: the frame moves at the first keyframe and then every fourth (1.2 m >= 1 m).
  EXPECT_EQ(reframes, 3);
}

}  // namespace
