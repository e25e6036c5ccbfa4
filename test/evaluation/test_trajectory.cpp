// Trajectories in the evaluation: the wheels at scan stamps, frames and starts, the --out and --trace
// files and the trajectory plot's script; gnuplot and shell quoting.
#include "hglasm_odometry/evaluation/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "hglasm_odometry/evaluation/gnuplot.h"

namespace hglasm {
namespace {

std::vector<std::string> lines(const std::string& path) {
  std::vector<std::string> result;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}

std::size_t words(const std::string& line) {
  std::istringstream in(line);
  std::size_t count = 0;
  for (std::string word; in >> word;) ++count;
  return count;
}

OdometryBuffer wheels() {
  OdometryBuffer buffer(1e9);
  buffer.add(10.0, Pose2D(0.0, 0.0, 0.0));
  buffer.add(11.0, Pose2D(1.0, 0.0, 0.2));
  buffer.add(12.0, Pose2D(2.0, 1.0, 0.4));
  return buffer;
}

TEST(Trajectory, WheelsAtStampsInterpolateAndLeaveOutWhatTheyDoNotCover) {
  const std::vector<StampedPose> at = trajectoryAt(wheels(), {9.5, 10.5, 11.75, 12.5}, 0.0);
  ASSERT_EQ(at.size(), 2u);
  EXPECT_EQ(at[0].stamp, 10.5);
  EXPECT_DOUBLE_EQ(at[0].pose.x, 0.5);
  EXPECT_DOUBLE_EQ(at[0].pose.theta, 0.1);
  EXPECT_EQ(at[1].stamp, 11.75);
  EXPECT_DOUBLE_EQ(at[1].pose.y, 0.75);
  // Read 0.5 s later, stamped as asked; with extrapolation the span's ends are covered too.
  const std::vector<StampedPose> shifted = trajectoryAt(wheels(), {10.0, 11.0}, 0.0, 0.5);
  ASSERT_EQ(shifted.size(), 2u);
  EXPECT_EQ(shifted[1].stamp, 11.0);
  EXPECT_DOUBLE_EQ(shifted[1].pose.x, 1.5);
  EXPECT_EQ(trajectoryAt(wheels(), {9.5, 12.5}, 1.0).size(), 2u);
}

TEST(Trajectory, FollowedByMovesEachPoseByTheOffsetInItsOwnFrame) {
  const std::vector<StampedPose> base = {{1.0, Pose2D(1.0, 2.0, M_PI / 2)}};
  const std::vector<StampedPose> laser = followedBy(base, Pose2D(0.5, 0.0, 0.1));
  EXPECT_NEAR(laser[0].pose.x, 1.0, 1e-12);
  EXPECT_NEAR(laser[0].pose.y, 2.5, 1e-12);
  EXPECT_NEAR(laser[0].pose.theta, M_PI / 2 + 0.1, 1e-12);
}

TEST(Trajectory, StartedAtKeepsTheMotionsAndMovesTheStart) {
  const std::vector<StampedPose> wheel = {{1.0, Pose2D(5.0, 5.0, 1.0)}, {2.0, Pose2D(6.0, 5.5, 1.2)}};
  const Pose2D start(0.0, 0.0, -0.3);
  const std::vector<StampedPose> moved = startedAt(wheel, start);
  EXPECT_NEAR(moved[0].pose.x, 0.0, 1e-12);
  EXPECT_NEAR(moved[0].pose.theta, -0.3, 1e-12);
  const Pose2D before = relativePose(wheel[0].pose, wheel[1].pose);
  const Pose2D after = relativePose(moved[0].pose, moved[1].pose);
  EXPECT_NEAR(after.x, before.x, 1e-12);
  EXPECT_NEAR(after.y, before.y, 1e-12);
  EXPECT_NEAR(after.theta, before.theta, 1e-12);
  EXPECT_TRUE(startedAt({}, start).empty());
}

TEST(Trajectory, BlendedWithWheelsWeighsEachStepAndKeepsTheEstimatesWhereTheWheelsAreMissing) {
  // The estimate drives 1 m per step turning 0.1 rad; the wheels, started elsewhere, 0.8 m turning 0.3 rad.
  std::vector<StampedPose> estimate, wheels;
  Pose2D e, w(3.0, -2.0, 1.0);
  for (int i = 0; i < 4; ++i) {
    estimate.push_back({10.0 + i, e});
    if (i != 3) wheels.push_back({10.0 + i + 2e-4, w});  // within the stamp tolerance; none at the last
    e = e * Pose2D(1.0, 0.0, 0.1);
    w = w * Pose2D(0.8, 0.0, 0.3);
  }
  const auto step = [](const std::vector<StampedPose>& t, int i) {
    return relativePose(t[i].pose, t[i + 1].pose);
  };
  const std::vector<StampedPose> same = blendedWithWheels(estimate, wheels, 0.0, 0.0);
  const std::vector<StampedPose> half = blendedWithWheels(estimate, wheels, 0.5, 0.25);
  const std::vector<StampedPose> all = blendedWithWheels(estimate, wheels, 1.0, 1.0);
  ASSERT_EQ(half.size(), estimate.size());
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(same[i + 1].pose.x, estimate[i + 1].pose.x, 1e-12);
    EXPECT_NEAR(same[i + 1].pose.theta, estimate[i + 1].pose.theta, 1e-12);
  }
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(step(half, i).x, 0.9, 1e-12);
    EXPECT_NEAR(step(half, i).y, 0.0, 1e-12);
    EXPECT_NEAR(step(half, i).theta, 0.15, 1e-12);
    EXPECT_NEAR(step(all, i).x, 0.8, 1e-12);
    EXPECT_NEAR(step(all, i).theta, 0.3, 1e-12);
  }
  // The last step has no wheel pose at its end: the estimate's own.
  EXPECT_NEAR(step(all, 2).x, 1.0, 1e-12);
  EXPECT_NEAR(step(all, 2).theta, 0.1, 1e-12);
  EXPECT_NEAR(all[0].pose.x, 0.0, 1e-12);  // starts where the estimate does
  EXPECT_TRUE(blendedWithWheels({}, wheels, 0.5, 0.5).empty());
}

TEST(Trajectory, WritesStampPoseAndTheIncrementCovariance) {
  const std::string path = testing::TempDir() + "hglasm_trajectory.txt";
  const std::vector<StampedPose> trajectory = {{1.25, Pose2D(1.0, -2.0, 0.5)},
                                               {2.5, Pose2D(3.0, 4.0, -0.25)}};
  ASSERT_TRUE(writeTrajectory(path, trajectory));
  EXPECT_EQ(lines(path), (std::vector<std::string>{"1.250000 1.000000 -2.000000 0.500000",
                                                   "2.500000 3.000000 4.000000 -0.250000"}));
  Eigen::Matrix3d covariance;
  covariance << 1e-4, 2e-5, 3e-6, 2e-5, 4e-4, 5e-6, 3e-6, 5e-6, 6e-3;
  const std::vector<Eigen::Matrix3d> covariances(2, covariance);
  ASSERT_TRUE(writeTrajectory(path, trajectory, &covariances));
  EXPECT_EQ(lines(path)[1], "2.500000 3.000000 4.000000 -0.250000 0.0001 2e-05 3e-06 0.0004 5e-06 0.006");
  std::remove(path.c_str());
  EXPECT_FALSE(writeTrajectory("/nonexistent/trajectory.txt", trajectory));
}

/// The numbers of one line ("nan" read as NaN).
std::vector<double> numbers(const std::string& line) {
  std::vector<double> values;
  std::istringstream in(line);
  for (std::string field; in >> field;) values.push_back(field == "nan" ? NAN : std::stod(field));
  return values;
}

TEST(Trajectory, RelationErrorsGiveEachRelationsSignedResidualsOfBothTrajectories) {
  const std::string path = testing::TempDir() + "hglasm_relation_errors.txt";
  const std::vector<Relation> relations = {{0.0, 1.0, Pose2D(1.0, 0.0, 0.0)},
                                           {0.0, 2.0, Pose2D(2.0, 0.0, 0.1)}};
  // The laser 0.1 m to the left at 1 s and 0.02 rad over at 2 s; the wheels 0.1 m short and 0.05 rad over
  // at 1 s, and without a pose at 2 s.
  const std::vector<StampedPose> laser = {
      {0.0, Pose2D()}, {1.0, Pose2D(1.0, 0.1, 0.0)}, {2.0, Pose2D(2.0, 0.0, 0.12)}};
  const std::vector<StampedPose> wheels = {{0.0, Pose2D()}, {1.0, Pose2D(0.9, 0.0, 0.05)}};
  ASSERT_TRUE(writeRelationErrors(path, relations, laser, wheels));
  const std::vector<std::string> written = lines(path);
  ASSERT_EQ(written.size(), 3u);
  EXPECT_EQ(written[0].substr(0, 12), "# t1 span re");
  const std::vector<double> first = numbers(written[1]), second = numbers(written[2]);
  ASSERT_EQ(first.size(), 15u);
  ASSERT_EQ(second.size(), 15u);
  const double deg = 180.0 / M_PI;
  const std::vector<double> expected_first = {0.0,  1.0, 1.0,        0.0, 0.0,          // the relation
                                              0.0,  0.1, 0.0,        0.1, 0.0,          // the laser
                                              -0.1, 0.0, 0.05 * deg, 0.1, 0.05 * deg};  // the wheels
  for (std::size_t i = 0; i < expected_first.size(); ++i) EXPECT_NEAR(first[i], expected_first[i], 1e-4) << i;
  const std::vector<double> expected_second = {0.0, 2.0, 2.0,        0.0, 0.1 * deg,
                                               0.0, 0.0, 0.02 * deg, 0.0, 0.02 * deg};
  for (std::size_t i = 0; i < expected_second.size(); ++i)
    EXPECT_NEAR(second[i], expected_second[i], 1e-4) << i;
  for (std::size_t i = 10; i < 15; ++i) EXPECT_TRUE(std::isnan(second[i])) << i;
  std::remove(path.c_str());
  EXPECT_FALSE(writeRelationErrors("/nonexistent/errors.txt", relations, laser, wheels));
}

TEST(Trajectory, TraceHasAHeaderNamingEveryColumnAndALinePerUpdate) {
  const std::string path = testing::TempDir() + "hglasm_trace.txt";
  std::vector<TrackerUpdate> updates(3);
  updates[1].matched = true;
  updates[1].pose = Pose2D(1.0, 2.0, 0.5);
  ASSERT_TRUE(writeTrackerTrace(path, updates));
  const std::vector<std::string> trace = lines(path);
  ASSERT_EQ(trace.size(), 4u);
  ASSERT_EQ(trace[0].substr(0, 2), "# ");
  for (std::size_t i = 1; i < trace.size(); ++i) EXPECT_EQ(words(trace[i]), words(trace[0]) - 1) << trace[i];
  EXPECT_EQ(trace[2].substr(0, 31), "0.000000 1.0000 2.0000 0.50000 ");
  std::remove(path.c_str());
}

TEST(Trajectory, PlotScriptQuotesPathsAndTitleAndLeavesOutAMissingTrajectory) {
  const std::string both = trajectoryPlotScript("/tmp/it's.png", "a 'b'", "/tmp/l.txt", "/tmp/w.txt");
  EXPECT_NE(both.find("set output '/tmp/it''s.png'\n"), std::string::npos) << both;
  EXPECT_NE(both.find("set title 'a ''b''' noenhanced"), std::string::npos) << both;
  EXPECT_NE(both.find("plot '/tmp/w.txt' using 2:3"), std::string::npos) << both;
  EXPECT_NE(both.find(", '/tmp/l.txt' using 2:3"), std::string::npos) << both;
  const std::string laser_only = trajectoryPlotScript("/tmp/p.png", "t", "/tmp/l.txt", "");
  EXPECT_EQ(laser_only.find("wheel odometry"), std::string::npos) << laser_only;
  EXPECT_NE(laser_only.find("plot '/tmp/l.txt' using 2:3"), std::string::npos) << laser_only;
  std::string error;
  EXPECT_FALSE(plotTrajectories(testing::TempDir() + "hglasm_none.png", "t", {}, {}, &error));
  EXPECT_EQ(error, "no trajectory to plot into " + testing::TempDir() + "hglasm_none.png");
}

TEST(Trajectory, PlotIntoADirectoryThatDoesNotExistSaysWhichFileItCannotWrite) {
  const std::string png = testing::TempDir() + "hglasm_no_such_directory/plot.png";
  std::string error;
  EXPECT_FALSE(plotTrajectories(png, "t", {{0.0, Pose2D()}, {1.0, Pose2D(1.0, 0.0, 0.0)}}, {}, &error));
  EXPECT_EQ(error, "cannot write " + png + ".laser.txt");
}

TEST(Gnuplot, QuotesForGnuplotAndForTheShell) {
  EXPECT_EQ(gnuplotQuote("it's"), "'it''s'");
  EXPECT_EQ(gnuplotQuote(""), "''");
  EXPECT_EQ(shellQuote("it's $HOME"), "'it'\\''s $HOME'");
}

}  // namespace
}  // namespace hglasm
