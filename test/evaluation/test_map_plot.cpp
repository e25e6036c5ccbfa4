// The map picture's data: scan points at known poses land at known world coordinates, one per cell; the
// frame, grid and equal-scale settings of the gnuplot script; the data file's blocks.
#include "hglasm_odometry/evaluation/map_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace hglasm {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Reads a gnuplot data file's blocks ('x y' lines; '#' comments; two blank lines end a block).
std::vector<std::vector<Eigen::Vector2d>> readBlocks(const std::string& path) {
  std::vector<std::vector<Eigen::Vector2d>> blocks(1);
  std::ifstream in(path);
  std::string line;
  int blank = 0;
  while (std::getline(in, line)) {
    if (line.empty()) {
      if (++blank == 2) blocks.emplace_back();
      continue;
    }
    blank = 0;
    if (line[0] == '#') continue;
    std::istringstream fields(line);
    double x = 0.0, y = 0.0;
    fields >> x >> y;
    blocks.back().emplace_back(x, y);
  }
  if (blocks.back().empty()) blocks.pop_back();
  return blocks;
}

TEST(MapPlot, PointsAreTheScansAtTheirPoses) {
  // One point 2 m ahead of the laser, one 1 m to its left.
  const std::vector<std::vector<Eigen::Vector2d>> scans(2, {{2.0, 0.0}, {0.0, 1.0}});
  const std::vector<Pose2D> poses = {Pose2D(1.0, 1.0, 0.0), Pose2D(10.0, -3.0, M_PI / 2)};
  MapPlotOptions options;
  options.cell = 0.0;
  const std::vector<Eigen::Vector2d> points = mapPoints(scans, poses, options);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_NEAR((points[0] - Eigen::Vector2d(3.0, 1.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((points[1] - Eigen::Vector2d(1.0, 2.0)).norm(), 0.0, 1e-12);
  // Facing +y: ahead is +y, left is -x.
  EXPECT_NEAR((points[2] - Eigen::Vector2d(10.0, -1.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((points[3] - Eigen::Vector2d(9.0, -3.0)).norm(), 0.0, 1e-12);
}

TEST(MapPlot, OnePointPerCellSkippedScansAndPoses) {
  // Three scans seeing the same wall point (within a cell) and one far one.
  const std::vector<std::vector<Eigen::Vector2d>> scans = {
      {{1.0, 0.0}}, {{1.01, 0.01}}, {{1.0, 0.0}, {5.0, 0.0}}, {{7.0, 0.0}}};
  const std::vector<Pose2D> poses = {Pose2D(), Pose2D(), Pose2D(), Pose2D(kNaN, 0.0, 0.0)};
  MapPlotOptions options;
  options.cell = 0.05;
  std::vector<Eigen::Vector2d> points = mapPoints(scans, poses, options);
  ASSERT_EQ(points.size(), 2u);  // the 4th scan has no pose
  EXPECT_EQ(points[0], Eigen::Vector2d(1.0, 0.0));
  EXPECT_EQ(points[1], Eigen::Vector2d(5.0, 0.0));
  options.cell = 0.0;
  options.scan_step = 2;  // scans 0 and 2
  points = mapPoints(scans, poses, options);
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[2], Eigen::Vector2d(5.0, 0.0));
  options.max_range = 4.0;  // the point 5 m from the laser is left out
  points = mapPoints(scans, poses, options);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[1], Eigen::Vector2d(1.0, 0.0));
}

TEST(MapPlot, LaserPosesIncludeTheMountAndAlignTheWheels) {
  const std::vector<StampedPose> base = {{10.0, Pose2D(1.0, 0.0, M_PI / 2)},
                                         {10.2, Pose2D(1.0, 1.0, M_PI / 2)}};
  const Pose2D mount(0.5, 0.0, 0.0);  // laser 0.5 m ahead of the base
  const std::vector<Pose2D> laser = laserPosesAtStamps({9.9, 10.0, 10.2}, base, mount);
  ASSERT_EQ(laser.size(), 3u);
  EXPECT_FALSE(laser[0].isFinite());  // no base pose at 9.9
  EXPECT_NEAR(laser[1].x, 1.0, 1e-12);
  EXPECT_NEAR(laser[1].y, 0.5, 1e-12);
  EXPECT_NEAR(laser[2].y, 1.5, 1e-12);
  EXPECT_NEAR(laser[2].theta, M_PI / 2, 1e-12);

  // Wheel poses in another frame: moved onto the laser's at the first index both have.
  const std::vector<Pose2D> wheel = {Pose2D(0.0, 0.0, 0.0), Pose2D(5.0, 5.0, 0.0), Pose2D(5.0, 6.0, 0.0)};
  const std::vector<Pose2D> aligned = alignedTo(laser, wheel);
  EXPECT_NEAR(aligned[1].x, laser[1].x, 1e-12);
  EXPECT_NEAR(aligned[1].y, laser[1].y, 1e-12);
  EXPECT_NEAR(aligned[1].theta, laser[1].theta, 1e-12);
  // 1 m along the wheels' x is 1 m along the laser's y (rotated by 90 degrees).
  EXPECT_NEAR(aligned[2].x, laser[1].x - 1.0, 1e-12);
  EXPECT_NEAR(aligned[2].y, laser[1].y, 1e-12);
}

TEST(MapPlot, FrameIsRoundedToTheGridAndSharedByTheViews) {
  MapPlotOptions options;
  options.margin = 0.5;
  options.panel_pixels = 1000;
  const MapFrame frame = mapFrame({{{0.2, -3.3}, {12.7, 4.1}}, {{-1.2, 0.0}}}, options);
  EXPECT_DOUBLE_EQ(frame.grid, 1.0);
  EXPECT_DOUBLE_EQ(frame.x_min, -2.0);
  EXPECT_DOUBLE_EQ(frame.x_max, 14.0);
  EXPECT_DOUBLE_EQ(frame.y_min, -4.0);
  EXPECT_DOUBLE_EQ(frame.y_max, 5.0);
  EXPECT_DOUBLE_EQ(frame.label, 1.0);  // 1 m is 66 px
  // A 500 m map on 1000 pixels: 1 m lines would be 2 px apart, widened to 2 m; labels every 50 m.
  const MapFrame large = mapFrame({{{0.0, 0.0}, {499.0, 10.0}}}, options);
  EXPECT_DOUBLE_EQ(large.grid, 2.0);
  EXPECT_DOUBLE_EQ(large.label, 50.0);
  // Two stray far points among 1000 in [0, 9.99] x [0, 0.999] do not stretch the frame.
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 1000; ++i) points.emplace_back(0.01 * i, 0.001 * i);
  points.emplace_back(50.0, -30.0);
  points.emplace_back(-40.0, 60.0);
  const MapFrame trimmed = mapFrame({points}, options);
  EXPECT_DOUBLE_EQ(trimmed.x_min, -1.0);
  EXPECT_DOUBLE_EQ(trimmed.x_max, 11.0);
  EXPECT_DOUBLE_EQ(trimmed.y_min, -1.0);
  EXPECT_DOUBLE_EQ(trimmed.y_max, 2.0);
}

TEST(MapPlot, ScriptHasEqualScaleSharedRangesAndTheMetreGrid) {
  MapPlotOptions options;
  options.panel_pixels = 800;
  options.title = "fr079";
  MapFrame frame;
  frame.x_min = -2.0, frame.x_max = 38.0, frame.y_min = -5.0, frame.y_max = 15.0;
  frame.grid = 1.0, frame.label = 5.0;
  std::vector<MapView> views(2);
  views[0].title = "laser odometry";
  views[1].title = "wheel odometry";
  views[1].colour = "#d62728";
  const std::string script = mapPlotScript("map.png", "map.dat", views, frame, options);
  EXPECT_NE(script.find("set size ratio -1\n"), std::string::npos);
  EXPECT_NE(script.find("title 'fr079 (one point per 5 cm cell, points within 20 m, grid lines every 1 m)'"),
            std::string::npos);
  EXPECT_NE(script.find("set xrange [-2:38]\n"), std::string::npos);
  EXPECT_NE(script.find("set yrange [-5:15]\n"), std::string::npos);
  EXPECT_NE(script.find("set xtics 5\n"), std::string::npos);
  EXPECT_NE(script.find("set mxtics 5\n"), std::string::npos);  // minor lines every metre
  // Wider than tall: one above the other, 800 x 400 px plot areas.
  EXPECT_NE(script.find("set multiplot layout 2,1"), std::string::npos);
  EXPECT_NE(script.find("size 910,1010 "), std::string::npos);
  EXPECT_NE(script.find("'map.dat' index 2 using 1:2 with dots lc rgb '#d62728'"), std::string::npos);
  EXPECT_NE(script.find("'map.dat' index 3 using 1:2 with lines"), std::string::npos);
  // Ranges set once for every panel (no per-panel autoscale).
  EXPECT_EQ(script.find("autoscale"), std::string::npos);
  frame.y_max = 45.0;  // taller than wide: side by side
  EXPECT_NE(mapPlotScript("map.png", "map.dat", views, frame, options).find("set multiplot layout 1,2"),
            std::string::npos);
}

TEST(MapPlot, DataFileHoldsEachViewsPointsAndPath) {
  const std::string png = ::testing::TempDir() + "map_plot_test.png";
  const std::vector<std::vector<Eigen::Vector2d>> scans = {{{1.0, 0.0}}, {{1.0, 0.0}}};
  std::vector<MapView> views(2);
  views[0].laser_poses = {Pose2D(0.0, 0.0, 0.0), Pose2D(1.0, 0.0, 0.0)};
  views[1].laser_poses = {Pose2D(0.0, 0.0, 0.0), Pose2D(kNaN, 0.0, 0.0)};
  std::string script, error;
  ASSERT_TRUE(writeMapFiles(png, scans, views, MapPlotOptions(), &script, &error)) << error;
  const auto blocks = readBlocks(png + ".map.dat");
  ASSERT_EQ(blocks.size(), 4u);
  ASSERT_EQ(blocks[0].size(), 2u);
  EXPECT_EQ(blocks[0][1], Eigen::Vector2d(2.0, 0.0));
  ASSERT_EQ(blocks[1].size(), 2u);  // the laser's path
  EXPECT_EQ(blocks[1][1], Eigen::Vector2d(1.0, 0.0));
  ASSERT_EQ(blocks[2].size(), 1u);
  ASSERT_EQ(blocks[3].size(), 1u);
  EXPECT_TRUE(std::ifstream(script).good());
  std::remove(script.c_str());
  std::remove((png + ".map.dat").c_str());
}

}  // namespace
}  // namespace hglasm
