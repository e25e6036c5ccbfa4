// The local map: the last keyframes at their poses, in the newest keyframe's frame.
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

TEST(LocalMap, KeepsTheLastKeyframesAndExpressesThemInTheNewestFrame) {
  LocalMapOptions options;
  options.keyframes = 3;
  options.resolution = 0.0;
  LocalMap map(options);
  EXPECT_TRUE(map.empty());
  for (int k = 0; k < 5; ++k) map.add(Pose2D(1.0 * k, 0.0, 0.1 * k), {Eigen::Vector2d(2.0, 0.0)});
  ASSERT_EQ(map.keyframeCount(), 3u);
  EXPECT_NEAR(map.frame().x, 4.0, 1e-12);
  EXPECT_NEAR(map.frame().theta, 0.4, 1e-12);
  // Oldest first: keyframes 2, 3, 4, each point 2 m ahead of its keyframe, seen from keyframe 4.
  const hglasm::ReferencePoints& reference = map.reference();
  ASSERT_EQ(reference.size(), 3u);
  EXPECT_EQ(reference.scan_starts, (std::vector<std::size_t>{0, 1, 2}));
  for (int k = 2; k <= 4; ++k) {
    const Eigen::Vector2d expected =
        map.frame().inverse() * (Pose2D(1.0 * k, 0.0, 0.1 * k) * Eigen::Vector2d(2.0, 0.0));
    EXPECT_NEAR((reference.points[k - 2] - expected).norm(), 0.0, 1e-12) << "keyframe " << k;
  }
  EXPECT_NEAR((reference.points[2] - Eigen::Vector2d(2.0, 0.0)).norm(), 0.0, 1e-12)
      << "the newest keyframe's points are its own";
  map.clear();
  EXPECT_TRUE(map.empty());
  EXPECT_TRUE(map.reference().empty());
}

TEST(LocalMap, KeyframesTooFarFromTheNewestLeave) {
  LocalMapOptions options;
  options.keyframes = 10;
  options.max_distance = 2.5;
  options.resolution = 0.0;
  LocalMap map(options);
  for (int k = 0; k < 6; ++k) map.add(Pose2D(1.0 * k, 0.0, 0.0), wall(3.0));
  EXPECT_EQ(map.keyframeCount(), 3u) << "keyframes 3, 4 and 5 are within 2.5 m of keyframe 5";
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

TEST(LocalMap, AtLeastOneKeyframe) {
  LocalMapOptions options;
  options.keyframes = 0;
  LocalMap map(options);
  map.add(Pose2D(), wall(2.0));
  EXPECT_EQ(map.keyframeCount(), 1u);
}

}  // namespace
