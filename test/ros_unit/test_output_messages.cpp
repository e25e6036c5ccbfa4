// The node's outgoing messages from a tracker update: ~odom (frames, pose, covariances, a non-finite
// velocity), ~match (enum constants, clamped counts, NaN-free floats, poses only for attempted matches, the
// scan's frame), the ~ga_population markers (finite individuals only, heading segments, arrows) and the
// ~local_map cloud (fields, frame, points moved into odom_frame, finite only; not latched per the README)
// and the ~path history (newest poses, oldest first, each at its scan's stamp).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <sensor_msgs/point_cloud2_iterator.h>

#include "hglasm_odometry/ros/conversions.h"
#include "hglasm_odometry/ros/output_publisher.h"

namespace hglasm_odometry {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std_msgs::Header makeHeader(double stamp, const std::string& frame) {
  std_msgs::Header header;
  header.stamp = ros::Time(stamp);
  header.frame_id = frame;
  return header;
}

TEST(OdometryMsg, FramesPoseVelocityAndCovariances) {
  hglasm::TrackerUpdate update;
  update.pose = hglasm::Pose2D(1.5, -2.0, 0.5);
  update.pose_covariance = Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal();
  update.velocity = Eigen::Vector3d(0.4, -0.1, 0.2);
  update.velocity_covariance = Eigen::Vector3d(0.04, 0.05, 0.006).asDiagonal();
  const nav_msgs::Odometry odom = odometryMsgFromUpdate(update, makeHeader(12.5, "odom"), "base_link");
  EXPECT_EQ(odom.header.stamp, ros::Time(12.5));
  EXPECT_EQ(odom.header.frame_id, "odom");
  EXPECT_EQ(odom.child_frame_id, "base_link");
  EXPECT_EQ(odom.pose.pose, poseMsgFromPose2D(update.pose));
  EXPECT_EQ(odom.pose.covariance, covariance6x6FromPlanar(update.pose_covariance));
  EXPECT_EQ(odom.twist.twist.linear.x, 0.4);
  EXPECT_EQ(odom.twist.twist.linear.y, -0.1);
  EXPECT_EQ(odom.twist.twist.linear.z, 0.0);
  EXPECT_EQ(odom.twist.twist.angular.z, 0.2);
  EXPECT_EQ(odom.twist.covariance, covariance6x6FromPlanar(update.velocity_covariance));
}

TEST(OdometryMsg, NonFiniteVelocityIsPublishedAsZero) {
  hglasm::TrackerUpdate update;
  update.velocity = Eigen::Vector3d(0.4, kNaN, 0.2);
  const nav_msgs::Odometry odom = odometryMsgFromUpdate(update, makeHeader(1.0, "odom"), "base_link");
  EXPECT_EQ(odom.twist.twist.linear.x, 0.0);
  EXPECT_EQ(odom.twist.twist.linear.y, 0.0);
  EXPECT_EQ(odom.twist.twist.angular.z, 0.0);
}

TEST(MatchMsg, EnumsMapOntoTheMessageConstants) {
  EXPECT_EQ(toMsg(hglasm::MatchStatus::kOk), Match::STATUS_OK);
  EXPECT_EQ(toMsg(hglasm::MatchStatus::kNoReference), Match::STATUS_NO_REFERENCE);
  EXPECT_EQ(toMsg(hglasm::MatchStatus::kTooFewPoints), Match::STATUS_TOO_FEW_POINTS);
  EXPECT_EQ(toMsg(hglasm::MatchStatus::kLowFitness), Match::STATUS_LOW_FITNESS);
  EXPECT_EQ(toMsg(hglasm::MatchStatus::kMbicpFailed), Match::STATUS_MBICP_FAILED);
  EXPECT_EQ(toMsg(hglasm::MatchStatus::kMbicpNotConverged), Match::STATUS_MBICP_NOT_CONVERGED);
  EXPECT_EQ(toMsg(hglasm::MbicpStatus::kConverged), Match::MBICP_CONVERGED);
  EXPECT_EQ(toMsg(hglasm::MbicpStatus::kMaxIterations), Match::MBICP_MAX_ITERATIONS);
  EXPECT_EQ(toMsg(hglasm::MbicpStatus::kTooFewAssociations), Match::MBICP_TOO_FEW_ASSOCIATIONS);
  EXPECT_EQ(toMsg(hglasm::MbicpStatus::kDegenerate), Match::MBICP_DEGENERATE);
  EXPECT_EQ(toMsg(hglasm::PredictionSource::kOdometry), Match::PREDICTION_ODOMETRY);
  EXPECT_EQ(toMsg(hglasm::PredictionSource::kConstantVelocity), Match::PREDICTION_CONSTANT_VELOCITY);
  EXPECT_EQ(toMsg(hglasm::PredictionSource::kNone), Match::PREDICTION_NONE);
}

/// An attempted match with every field set.
hglasm::PipelineUpdate matchedUpdate() {
  hglasm::PipelineUpdate result;
  hglasm::TrackerUpdate& update = result.tracker;
  update.matched = true;
  update.new_keyframe = true;
  update.diagnostics.deskewed = true;
  update.diagnostics.prediction = hglasm::PredictionSource::kConstantVelocity;
  update.diagnostics.match.status = hglasm::MatchStatus::kMbicpNotConverged;
  update.diagnostics.match.mbicp_status = hglasm::MbicpStatus::kMaxIterations;
  update.diagnostics.match.pose = hglasm::Pose2D(0.5, 0.25, -0.125);
  update.diagnostics.match.prealigned_pose = hglasm::Pose2D(0.5, 0.125, -0.25);
  update.diagnostics.match.prealigned_fitness = 41000;
  update.diagnostics.match.prealigned_fitness_ratio = 0.75;
  update.diagnostics.match.evaluations = 1000;
  update.diagnostics.match.iterations = 30;
  update.diagnostics.match.associations = 250;
  update.diagnostics.match.rms_error = 0.03125;
  update.diagnostics.fitness_ratio = 0.625;
  update.diagnostics.search.box = hglasm::SearchBox{0.25, 0.5, 0.125};
  update.diagnostics.search.population = 100;
  update.keyframe_id = 7;
  update.diagnostics.map_keyframes = 3;
  update.diagnostics.leap_probability = 0.25;
  update.diagnostics.leap_deferred = true;
  update.diagnostics.learned.wheel_noise.xy = 2.0;
  update.diagnostics.learned.wheel_noise.theta = 0.5;
  update.diagnostics.learned.wheel_turn_scale = -0.0625;
  update.diagnostics.learned.laser_offset = Eigen::Vector2d(0.0625, -0.125);
  update.diagnostics.odometry_time_offset = 0.125;
  update.diagnostics.odometry_time_offset_estimate = 0.25;
  update.diagnostics.reanchored = true;
  result.laser_guess = hglasm::Pose2D(0.375, 0.25, 0.0);
  result.scan.points.resize(300);
  result.scan.invalid_count = 60;
  return result;
}

TEST(MatchMsg, AttemptedMatch) {
  const hglasm::PipelineUpdate result = matchedUpdate();
  const Match match = matchMsgFromUpdate(result, makeHeader(3.0, "/laser"), 12.5, 4);
  EXPECT_EQ(match.header.stamp, ros::Time(3.0));
  EXPECT_EQ(match.header.frame_id, "laser");
  EXPECT_TRUE(match.matched);
  EXPECT_FALSE(match.fallback);
  EXPECT_TRUE(match.new_keyframe);
  EXPECT_TRUE(match.deskewed);
  EXPECT_EQ(match.prediction_source, Match::PREDICTION_CONSTANT_VELOCITY);
  EXPECT_EQ(match.status, Match::STATUS_MBICP_NOT_CONVERGED);
  EXPECT_EQ(match.status_text, hglasm::toString(hglasm::MatchStatus::kMbicpNotConverged));
  EXPECT_EQ(match.mbicp_status, Match::MBICP_MAX_ITERATIONS);
  EXPECT_EQ(match.guess_pose, pose2DMsgFromPose2D(*result.laser_guess));
  EXPECT_EQ(match.prealigned_pose, pose2DMsgFromPose2D(result.tracker.diagnostics.match.prealigned_pose));
  EXPECT_EQ(match.final_pose, pose2DMsgFromPose2D(result.tracker.diagnostics.match.pose));
  EXPECT_EQ(match.fitness_ratio, 0.625f);
  EXPECT_EQ(match.prealigned_fitness, 41000u);
  EXPECT_EQ(match.prealigned_fitness_ratio, 0.75f);
  EXPECT_EQ(match.evaluations, 1000u);
  EXPECT_EQ(match.iterations, 30u);
  EXPECT_EQ(match.associations, 250u);
  EXPECT_EQ(match.rms_error, 0.03125f);
  EXPECT_EQ(match.search_box.x, 0.25);
  EXPECT_EQ(match.search_box.y, 0.5);
  EXPECT_EQ(match.search_box.theta, 0.125);
  EXPECT_EQ(match.search_population, 100u);
  EXPECT_EQ(match.keyframe_id, 7u);
  EXPECT_EQ(match.map_keyframes, 3u);
  EXPECT_EQ(match.leap_probability, 0.25f);
  EXPECT_TRUE(match.leap_deferred);
  EXPECT_EQ(match.noise_scale_xy, 2.0f);
  EXPECT_EQ(match.noise_scale_theta, 0.5f);
  EXPECT_EQ(match.wheel_turn_scale, -0.0625f);
  EXPECT_EQ(match.laser_offset[0], 0.0625f);
  EXPECT_EQ(match.laser_offset[1], -0.125f);
  EXPECT_EQ(match.odometry_time_offset, 0.125f);
  EXPECT_EQ(match.odometry_time_offset_estimate, 0.25f);
  EXPECT_TRUE(match.reanchored);
  EXPECT_EQ(match.valid_points, 300u);
  EXPECT_EQ(match.invalid_points, 60u);
  EXPECT_EQ(match.total_ms, 12.5f);
  EXPECT_EQ(match.dropped_scans, 4u);
}

TEST(MatchMsg, AStaleScanSaysSo) {
  hglasm::PipelineUpdate result;
  result.tracker.stale = true;
  const Match match = matchMsgFromUpdate(result, makeHeader(3.0, "laser"), 0.0, 0);
  EXPECT_EQ(match.status, Match::STATUS_STALE);
  EXPECT_EQ(match.status_text, "stale");
  EXPECT_FALSE(match.matched);
  EXPECT_FALSE(match.reset);
}

TEST(MatchMsg, NoPosesWithoutAnAttemptedMatch) {
  hglasm::PipelineUpdate result = matchedUpdate();
  result.tracker.matched = false;
  const Match match = matchMsgFromUpdate(result, makeHeader(3.0, "laser"), 1.0, 0);
  EXPECT_FALSE(match.matched);
  EXPECT_EQ(match.guess_pose, geometry_msgs::Pose2D());
  EXPECT_EQ(match.prealigned_pose, geometry_msgs::Pose2D());
  EXPECT_EQ(match.final_pose, geometry_msgs::Pose2D());
}

TEST(MatchMsg, NegativeCountsAreZeroAndNonFiniteNumbersToo) {
  hglasm::PipelineUpdate result = matchedUpdate();
  result.tracker.diagnostics.match.evaluations = -1;
  result.tracker.diagnostics.match.iterations = -2;
  result.tracker.diagnostics.match.associations = -3;
  result.tracker.keyframe_id = -4;
  result.tracker.diagnostics.map_keyframes = -5;
  result.tracker.diagnostics.search.population = -6;
  result.scan.invalid_count = -7;
  result.tracker.diagnostics.fitness_ratio = kNaN;
  result.tracker.diagnostics.match.rms_error = std::numeric_limits<double>::infinity();
  result.tracker.diagnostics.leap_probability = kNaN;
  result.tracker.diagnostics.match.prealign_ms = kNaN;
  const Match match = matchMsgFromUpdate(result, makeHeader(3.0, "laser"), kNaN, 0);
  EXPECT_EQ(match.evaluations, 0u);
  EXPECT_EQ(match.iterations, 0u);
  EXPECT_EQ(match.associations, 0u);
  EXPECT_EQ(match.keyframe_id, 0u);
  EXPECT_EQ(match.map_keyframes, 0u);
  EXPECT_EQ(match.search_population, 0u);
  EXPECT_EQ(match.invalid_points, 0u);
  EXPECT_EQ(match.fitness_ratio, 0.0f);
  EXPECT_EQ(match.rms_error, 0.0f);
  EXPECT_EQ(match.leap_probability, 0.0f);
  EXPECT_EQ(match.prealign_ms, 0.0f);
  EXPECT_EQ(match.total_ms, 0.0f);
}

TEST(PopulationMarkers, SegmentsForFiniteIndividualsAndTwoArrows) {
  hglasm::Pose2D bad(1.0, 1.0, 0.0);
  bad.x = kNaN;
  const std::vector<hglasm::Pose2D> population = {hglasm::Pose2D(1.0, 2.0, 0.0), bad,
                                                  hglasm::Pose2D(-1.0, 0.5, M_PI / 2)};
  const hglasm::Pose2D estimate(0.5, 0.5, 0.25);
  const hglasm::Pose2D guess(0.25, 0.5, 0.0);
  const visualization_msgs::MarkerArray markers =
      populationMarkers(makeHeader(4.0, "odom"), population, estimate, guess);
  ASSERT_EQ(markers.markers.size(), 3u);

  const visualization_msgs::Marker& individuals = markers.markers[0];
  EXPECT_EQ(individuals.header.frame_id, "odom");
  EXPECT_EQ(individuals.header.stamp, ros::Time(4.0));
  EXPECT_EQ(individuals.ns, "ga_population");
  EXPECT_EQ(individuals.id, 0);
  EXPECT_EQ(individuals.type, visualization_msgs::Marker::LINE_LIST);
  ASSERT_EQ(individuals.points.size(), 4u);  // the NaN individual left out
  EXPECT_EQ(individuals.points[0].x, 1.0);
  EXPECT_EQ(individuals.points[0].y, 2.0);
  EXPECT_DOUBLE_EQ(individuals.points[1].x, 1.08);  // 8 cm along the heading
  EXPECT_DOUBLE_EQ(individuals.points[1].y, 2.0);
  EXPECT_EQ(individuals.points[2].x, -1.0);
  EXPECT_NEAR(individuals.points[3].x, -1.0, 1e-15);
  EXPECT_DOUBLE_EQ(individuals.points[3].y, 0.58);

  const visualization_msgs::Marker& estimate_arrow = markers.markers[1];
  const visualization_msgs::Marker& guess_arrow = markers.markers[2];
  for (const visualization_msgs::Marker* arrow : {&estimate_arrow, &guess_arrow}) {
    EXPECT_EQ(arrow->ns, "ga_estimate");
    EXPECT_EQ(arrow->type, visualization_msgs::Marker::ARROW);
    EXPECT_EQ(arrow->header.frame_id, "odom");
  }
  EXPECT_EQ(estimate_arrow.id, 1);
  EXPECT_EQ(estimate_arrow.pose, poseMsgFromPose2D(estimate));
  EXPECT_GT(estimate_arrow.color.g, estimate_arrow.color.b);  // green
  EXPECT_EQ(guess_arrow.id, 2);
  EXPECT_EQ(guess_arrow.pose, poseMsgFromPose2D(guess));
  EXPECT_GT(guess_arrow.color.b, guess_arrow.color.g);  // blue
}

TEST(PopulationMarkers, EmptyPopulationStillDrawsTheArrows) {
  const visualization_msgs::MarkerArray markers =
      populationMarkers(makeHeader(4.0, "odom"), {}, hglasm::Pose2D(), hglasm::Pose2D());
  ASSERT_EQ(markers.markers.size(), 3u);
  EXPECT_TRUE(markers.markers[0].points.empty());
}

/// The x, y, z values of a cloud's points, read through its fields' offsets.
std::vector<Eigen::Vector3f> cloudPoints(const sensor_msgs::PointCloud2& cloud) {
  std::vector<Eigen::Vector3f> points;
  sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  for (; x != x.end(); ++x, ++y, ++z) points.emplace_back(*x, *y, *z);
  return points;
}

TEST(LocalMapCloud, PointsMovedIntoTheHeadersFrameAsXYZFloat32) {
  const std_msgs::Header header = makeHeader(12.5, "odom");
  // The map's frame: 1 m ahead, 2 m left, turned a quarter: (1, 0) lands at (1, 3), (0, -1) at (2, 2).
  const hglasm::Pose2D frame(1.0, 2.0, M_PI / 2);
  const std::vector<Eigen::Vector2d> points{{1.0, 0.0}, {0.0, -1.0}, {0.0, 0.0}};
  const sensor_msgs::PointCloud2 cloud = pointCloudMsgFromPoints(header, frame, points);
  EXPECT_EQ(cloud.header.frame_id, "odom");
  EXPECT_EQ(cloud.header.stamp, ros::Time(12.5));
  EXPECT_EQ(cloud.height, 1u);
  EXPECT_EQ(cloud.width, 3u);
  EXPECT_TRUE(cloud.is_dense);
  EXPECT_FALSE(cloud.is_bigendian);
  ASSERT_EQ(cloud.fields.size(), 3u);
  const char* names[] = {"x", "y", "z"};
  for (std::uint32_t i = 0; i < 3; ++i) {
    EXPECT_EQ(cloud.fields[i].name, names[i]);
    EXPECT_EQ(cloud.fields[i].datatype, sensor_msgs::PointField::FLOAT32);
    EXPECT_EQ(cloud.fields[i].count, 1u);
    EXPECT_EQ(cloud.fields[i].offset, 4u * i);
  }
  EXPECT_EQ(cloud.point_step, 12u);
  EXPECT_EQ(cloud.row_step, 36u);
  EXPECT_EQ(cloud.data.size(), 36u);
  const std::vector<Eigen::Vector3f> got = cloudPoints(cloud);
  ASSERT_EQ(got.size(), 3u);
  const std::vector<Eigen::Vector3f> expected{{1.0f, 3.0f, 0.0f}, {2.0f, 2.0f, 0.0f}, {1.0f, 2.0f, 0.0f}};
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR((got[i] - expected[i]).norm(), 0.0f, 1e-6f) << i;
}

TEST(LocalMapCloud, NonFinitePointsAreLeftOutAndANonFiniteFrameGivesNone) {
  const std_msgs::Header header = makeHeader(1.0, "odom");
  const std::vector<Eigen::Vector2d> points{{1.0, 0.0}, {kNaN, 0.0}, {1e300, 0.0}, {0.0, 2.0}};
  const sensor_msgs::PointCloud2 cloud = pointCloudMsgFromPoints(header, hglasm::Pose2D(), points);
  const std::vector<Eigen::Vector3f> got = cloudPoints(cloud);
  ASSERT_EQ(got.size(), 2u) << "NaN and a point beyond float's range are left out";
  EXPECT_EQ(cloud.width, 2u);
  EXPECT_EQ(got[0], Eigen::Vector3f(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(got[1], Eigen::Vector3f(0.0f, 2.0f, 0.0f));
  hglasm::Pose2D bad;
  bad.x = kNaN;
  const sensor_msgs::PointCloud2 none = pointCloudMsgFromPoints(header, bad, points);
  EXPECT_EQ(none.width, 0u);
  EXPECT_TRUE(none.data.empty());
  EXPECT_EQ(none.fields.size(), 3u) << "an empty cloud still says what its points would be";
  EXPECT_TRUE(pointCloudMsgFromPoints(header, hglasm::Pose2D(), {}).data.empty());
}

TEST(PathMsg, TheNewestPosesOldestFirstInTheHeadersFrame) {
  PathHistory history(3);
  for (int i = 0; i < 5; ++i) history.add(ros::Time(10.0 + i), hglasm::Pose2D(i, -i, 0.1 * i));
  EXPECT_EQ(history.size(), 3u);
  nav_msgs::Path path;
  history.toMsg(makeHeader(14.0, "odom"), &path);
  EXPECT_EQ(path.header.stamp, ros::Time(14.0));
  EXPECT_EQ(path.header.frame_id, "odom");
  ASSERT_EQ(path.poses.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(path.poses[i].header.stamp, ros::Time(12.0 + i));
    EXPECT_EQ(path.poses[i].header.frame_id, "odom");
    EXPECT_EQ(path.poses[i].pose, poseMsgFromPose2D(hglasm::Pose2D(2 + i, -2 - i, 0.1 * (2 + i))));
  }
  history.clear();
  history.add(ros::Time(20.0), hglasm::Pose2D(7.0, 0.0, 0.0));
  history.toMsg(makeHeader(20.0, "odom"), &path);  // the message is reused: shorter now
  ASSERT_EQ(path.poses.size(), 1u);
  EXPECT_EQ(path.poses[0].pose.position.x, 7.0);
}

/// The rostest checks the connection says latching 0; the README's topic table must say so too.
TEST(LocalMapCloud, TheReadmeDocumentsTheTopicAsNotLatched) {
  std::ifstream readme(HGLASM_SOURCE_DIR "/README.md");
  ASSERT_TRUE(readme.good());
  std::string line, row;
  while (std::getline(readme, line)) {
    if (line.rfind("| out | `~local_map` |", 0) == 0) row = line;
  }
  ASSERT_FALSE(row.empty()) << "no ~local_map row in the README's topics table";
  EXPECT_NE(row.find("sensor_msgs/PointCloud2"), std::string::npos) << row;
  EXPECT_NE(row.find("not latched"), std::string::npos) << row;
  EXPECT_NE(row.find("only while someone subscribes"), std::string::npos) << row;
}

}  // namespace
}  // namespace hglasm_odometry
