// Message conversions: REP-117 ranges, descending and 360-degree scans, upside-down mounts, covariance.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>

#include <tf2/LinearMath/Quaternion.h>

#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/ros/conversions.h"

namespace hglasm_odometry {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

sensor_msgs::LaserScan makeScan(int beams, double angle_min, double increment, float range) {
  sensor_msgs::LaserScan msg;
  msg.angle_min = angle_min;
  msg.angle_increment = increment;
  msg.angle_max = angle_min + increment * (beams - 1);
  msg.range_min = 0.1f;
  msg.range_max = 30.0f;
  msg.ranges.assign(beams, range);
  return msg;
}

geometry_msgs::Transform makeTransform(double x, double y, double z, double roll, double pitch, double yaw) {
  tf2::Quaternion q;
  q.setRPY(roll, pitch, yaw);
  geometry_msgs::Transform t;
  t.translation.x = x;
  t.translation.y = y;
  t.translation.z = z;
  t.rotation.x = q.x();
  t.rotation.y = q.y();
  t.rotation.z = q.z();
  t.rotation.w = q.w();
  return t;
}

/// Maps a laser point (in the laser's own frame) into the base frame with the full 3D transform.
Eigen::Vector2d projectWith3D(const geometry_msgs::Transform& t, const Eigen::Vector2d& p) {
  tf2::Quaternion q(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w);
  const tf2::Vector3 v = tf2::quatRotate(q, tf2::Vector3(p.x(), p.y(), 0.0)) +
                         tf2::Vector3(t.translation.x, t.translation.y, t.translation.z);
  return Eigen::Vector2d(v.x(), v.y());
}

TEST(RangeScanFromMsg, CopiesPolarFieldsAndKeepsInvalidRangesForTheCore) {
  sensor_msgs::LaserScan msg = makeScan(6, -0.5, 0.2, 2.0f);
  msg.ranges = {2.0f,
                std::numeric_limits<float>::quiet_NaN(),
                std::numeric_limits<float>::infinity(),
                -std::numeric_limits<float>::infinity(),
                0.0f,
                50.0f};
  const hglasm::RangeScan scan = rangeScanFromMsg(msg);
  ASSERT_EQ(scan.ranges.size(), 6u);
  EXPECT_FLOAT_EQ(scan.angle_min, -0.5);
  EXPECT_NEAR(scan.angle_increment, 0.2, 1e-7);
  EXPECT_NEAR(scan.range_min, 0.1, 1e-7);
  EXPECT_NEAR(scan.range_max, 30.0, 1e-6);
  EXPECT_EQ(scan.time_increment, 0.0);  // makeScan leaves the beam times out, as converted logs do

  // Only the first beam is valid per REP-117 (NaN, +-inf, 0 and > range_max are not).
  hglasm::ScanError error = hglasm::ScanError::kBadAngles;
  const hglasm::Scan points = hglasm::scanFromRanges(scan, {}, &error);
  EXPECT_EQ(error, hglasm::ScanError::kNone);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points.invalid_count, 5);
  EXPECT_NEAR(points.points[0].x(), 2.0 * std::cos(-0.5), 1e-6);
  EXPECT_NEAR(points.points[0].y(), 2.0 * std::sin(-0.5), 1e-6);
}

TEST(RangeScanFromMsg, BeamTimesAreCopiedAndNonFiniteOnesDropped) {
  sensor_msgs::LaserScan msg = makeScan(3, 0.0, 0.1, 5.0f);
  msg.time_increment = 2.5e-5f;
  EXPECT_FLOAT_EQ(rangeScanFromMsg(msg).time_increment, 2.5e-5f);
  for (float broken : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    msg.time_increment = broken;
    EXPECT_EQ(rangeScanFromMsg(msg).time_increment, 0.0) << broken;
  }
}

TEST(RangeScanFromMsg, IntoAScanReusesItsStorage) {
  hglasm::RangeScan scan;
  rangeScanFromMsg(makeScan(360, -1.0, 0.01, 4.0f), &scan);
  const float* storage = scan.ranges.data();
  sensor_msgs::LaserScan next = makeScan(180, 0.5, 0.02, 2.0f);
  next.range_min = std::numeric_limits<float>::quiet_NaN();
  next.time_increment = 1e-4f;
  rangeScanFromMsg(next, &scan);
  EXPECT_EQ(scan.ranges.data(), storage);
  EXPECT_EQ(scan.ranges, next.ranges);
  // Every field as the returning conversion gives it.
  const hglasm::RangeScan fresh = rangeScanFromMsg(next);
  EXPECT_EQ(scan.angle_min, fresh.angle_min);
  EXPECT_EQ(scan.angle_increment, fresh.angle_increment);
  EXPECT_EQ(scan.range_min, fresh.range_min);
  EXPECT_EQ(scan.range_max, fresh.range_max);
  EXPECT_EQ(scan.time_increment, fresh.time_increment);
}

TEST(RangeScanFromMsg, NonFiniteRangeLimitsDoNotInvalidateEveryBeam) {
  sensor_msgs::LaserScan msg = makeScan(3, 0.0, 0.1, 5.0f);
  msg.range_min = std::numeric_limits<float>::quiet_NaN();
  msg.range_max = std::numeric_limits<float>::quiet_NaN();
  hglasm::RangeScan scan = rangeScanFromMsg(msg);
  EXPECT_EQ(scan.range_min, 0.0);
  EXPECT_TRUE(std::isinf(scan.range_max));
  EXPECT_EQ(hglasm::scanFromRanges(scan).size(), 3u);

  msg.range_min = -1.0f;
  msg.range_max = 0.0f;  // some drivers leave it unset
  scan = rangeScanFromMsg(msg);
  EXPECT_EQ(scan.range_min, 0.0);
  EXPECT_TRUE(std::isinf(scan.range_max));
}

TEST(RangeScanFromMsg, DescendingAnglesGiveTheSamePointsAsAscendingOnes) {
  // The same physical scan, stored from left to right and from right to left.
  const int beams = 181;
  sensor_msgs::LaserScan ascending = makeScan(beams, -M_PI / 2, M_PI / 180, 0.0f);
  for (int i = 0; i < beams; ++i) ascending.ranges[i] = 1.0f + 0.01f * i;
  sensor_msgs::LaserScan descending = makeScan(beams, M_PI / 2, -M_PI / 180, 0.0f);
  for (int i = 0; i < beams; ++i) descending.ranges[i] = ascending.ranges[beams - 1 - i];

  const hglasm::Scan a = hglasm::scanFromRanges(rangeScanFromMsg(ascending));
  const hglasm::Scan d = hglasm::scanFromRanges(rangeScanFromMsg(descending));
  ASSERT_EQ(a.size(), static_cast<std::size_t>(beams));
  ASSERT_EQ(d.size(), static_cast<std::size_t>(beams));
  for (int i = 0; i < beams; ++i) {
    EXPECT_NEAR(a.points[i].x(), d.points[beams - 1 - i].x(), 1e-5);
    EXPECT_NEAR(a.points[i].y(), d.points[beams - 1 - i].y(), 1e-5);
  }
  // Beam 0 of the descending scan is on the left (+y).
  EXPECT_GT(d.points.front().y(), 0.9);
}

TEST(RangeScanFromMsg, FullCircleScanAcrossPlusMinusPi) {
  // 360 beams starting just below +pi and wrapping through -pi: every direction exactly once.
  const int beams = 360;
  sensor_msgs::LaserScan msg = makeScan(beams, M_PI - 0.5 * M_PI / 180, 2 * M_PI / beams, 3.0f);
  const hglasm::Scan scan = hglasm::scanFromRanges(rangeScanFromMsg(msg));
  ASSERT_EQ(scan.size(), static_cast<std::size_t>(beams));
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& p : scan.points) {
    EXPECT_NEAR(p.norm(), 3.0, 1e-5);
    sum += p;
  }
  EXPECT_LT(sum.norm(), 1e-3);  // evenly spread around the circle
}

TEST(LaserMount, UprightMountIsTheYawAndTranslation) {
  LaserMount mount;
  std::string error;
  ASSERT_TRUE(laserMountFromTransform(makeTransform(0.3, -0.1, 0.2, 0.0, 0.0, 0.7), &mount, &error)) << error;
  EXPECT_FALSE(mount.upside_down);
  EXPECT_NEAR(mount.base_to_laser.x, 0.3, 1e-12);
  EXPECT_NEAR(mount.base_to_laser.y, -0.1, 1e-12);
  EXPECT_NEAR(mount.base_to_laser.theta, 0.7, 1e-12);
  EXPECT_NEAR(mount.tilt, 0.0, 1e-9);
}

TEST(LaserMount, UpsideDownMountMirrorsScansAndMatchesThe3DProjection) {
  // Rolled over (180 degrees about x) and yawed: the 2D projection is a reflection.
  for (double yaw : {0.0, 0.6, -2.5, M_PI}) {
    const geometry_msgs::Transform t = makeTransform(0.25, 0.05, 0.4, M_PI, 0.0, yaw);
    LaserMount mount;
    std::string error;
    ASSERT_TRUE(laserMountFromTransform(t, &mount, &error)) << error;
    EXPECT_TRUE(mount.upside_down);
    EXPECT_NEAR(mount.tilt, 0.0, 1e-6);

    sensor_msgs::LaserScan msg = makeScan(91, -M_PI / 4, M_PI / 180, 0.0f);
    for (int i = 0; i < 91; ++i) msg.ranges[i] = 1.0f + 0.02f * i;
    hglasm::ScanConversionOptions mirrored;
    mirrored.mirror = mount.upside_down;
    const hglasm::Scan plain = hglasm::scanFromRanges(rangeScanFromMsg(msg));
    const hglasm::Scan flipped = hglasm::scanFromRanges(rangeScanFromMsg(msg), mirrored);
    ASSERT_EQ(plain.size(), flipped.size());
    for (std::size_t i = 0; i < plain.size(); ++i) {
      const Eigen::Vector2d expected = projectWith3D(t, plain.points[i]);
      const Eigen::Vector2d actual = mount.base_to_laser * flipped.points[i];
      EXPECT_NEAR((expected - actual).norm(), 0.0, 1e-9) << "yaw " << yaw << " beam " << i;
    }
  }
}

TEST(LaserMount, PitchedUpsideDownMountIsAlsoAReflection) {
  // Upside down by pitching 180 degrees (about y) instead of rolling.
  const geometry_msgs::Transform t = makeTransform(0.0, 0.0, 0.3, 0.0, M_PI, 0.3);
  LaserMount mount;
  std::string error;
  ASSERT_TRUE(laserMountFromTransform(t, &mount, &error));
  EXPECT_TRUE(mount.upside_down);
  hglasm::ScanConversionOptions mirrored;
  mirrored.mirror = true;
  const Eigen::Vector2d p(1.0, 0.5);
  const Eigen::Vector2d mirrored_p(p.x(), -p.y());
  EXPECT_NEAR((projectWith3D(t, p) - mount.base_to_laser * mirrored_p).norm(), 0.0, 1e-9);
}

TEST(LaserMount, RejectsNonFiniteAndVerticalScanPlanes) {
  LaserMount mount;
  std::string error;
  geometry_msgs::Transform t = makeTransform(0, 0, 0, 0, 0, 0);
  t.translation.x = kNaN;
  EXPECT_FALSE(laserMountFromTransform(t, &mount, &error));
  EXPECT_FALSE(error.empty());
  t = makeTransform(0, 0, 0, 0, 0, 0);
  t.rotation.w = kInf;
  EXPECT_FALSE(laserMountFromTransform(t, &mount, &error));
  t.rotation.x = t.rotation.y = t.rotation.z = t.rotation.w = 0.0;
  EXPECT_FALSE(laserMountFromTransform(t, &mount, &error));
  // Scan plane vertical (rolled 90 degrees): rejected, or accepted with its tilt reported.
  error.clear();
  EXPECT_FALSE(laserMountFromTransform(makeTransform(0, 0, 0, M_PI / 2, 0.0, 0.0), &mount, &error) &&
               mount.tilt < 1.0)
      << "a vertical scan plane must be rejected or reported as tilted";
}

TEST(PoseConversions, RoundTripsAndNeverEmitNaN) {
  const hglasm::Pose2D pose(1.5, -2.0, 2.9);
  hglasm::Pose2D back;
  ASSERT_TRUE(pose2DFromPoseMsg(poseMsgFromPose2D(pose), &back));
  EXPECT_NEAR(back.x, 1.5, 1e-12);
  EXPECT_NEAR(back.y, -2.0, 1e-12);
  EXPECT_NEAR(back.theta, 2.9, 1e-12);
  ASSERT_TRUE(pose2DFromPose2DMsg(pose2DMsgFromPose2D(pose), &back));
  EXPECT_NEAR(back.theta, 2.9, 1e-12);

  hglasm::Pose2D bad;
  bad.x = kNaN;
  bad.theta = kInf;
  const geometry_msgs::Pose msg = poseMsgFromPose2D(bad);
  EXPECT_TRUE(std::isfinite(msg.position.x));
  EXPECT_TRUE(std::isfinite(msg.orientation.z) && std::isfinite(msg.orientation.w));
  EXPECT_NEAR(msg.orientation.w, 1.0, 1e-12);
  const geometry_msgs::Pose2D msg2 = pose2DMsgFromPose2D(bad);
  EXPECT_TRUE(std::isfinite(msg2.x) && std::isfinite(msg2.theta));
  const geometry_msgs::Transform tf = transformMsgFromPose2D(bad);
  EXPECT_TRUE(std::isfinite(tf.translation.x) && std::isfinite(tf.rotation.w));

  geometry_msgs::Pose nan_pose;
  nan_pose.orientation.w = 1.0;
  nan_pose.position.y = kNaN;
  back = pose;
  EXPECT_FALSE(pose2DFromPoseMsg(nan_pose, &back));
  EXPECT_EQ(back.x, pose.x);  // untouched
  geometry_msgs::Pose2D nan_pose2d;
  nan_pose2d.theta = kNaN;
  EXPECT_FALSE(pose2DFromPose2DMsg(nan_pose2d, &back));
}

TEST(PoseConversions, YawOfUnnormalisedAndDegenerateQuaternions) {
  geometry_msgs::Quaternion q = quaternionFromYaw(-1.2);
  q.x *= 3.0;
  q.y *= 3.0;
  q.z *= 3.0;
  q.w *= 3.0;
  EXPECT_NEAR(yawFromQuaternion(q), -1.2, 1e-12);
  geometry_msgs::Quaternion zero;
  zero.w = 0.0;
  EXPECT_EQ(yawFromQuaternion(zero), 0.0);
  geometry_msgs::Quaternion nan_q;
  nan_q.w = kNaN;
  EXPECT_EQ(yawFromQuaternion(nan_q), 0.0);
  EXPECT_NEAR(quaternionFromYaw(kNaN).w, 1.0, 1e-12);
}

TEST(PoseConversions, OdometryMessageGivesThePlanarPose) {
  nav_msgs::Odometry odom;
  odom.pose.pose.position.x = 3.0;
  odom.pose.pose.position.y = 4.0;
  odom.pose.pose.orientation = quaternionFromYaw(0.5);
  hglasm::Pose2D pose;
  ASSERT_TRUE(pose2DFromOdometryMsg(odom, &pose));
  EXPECT_NEAR(pose.x, 3.0, 1e-12);
  EXPECT_NEAR(pose.theta, 0.5, 1e-12);
  odom.pose.pose.orientation.z = kInf;
  EXPECT_FALSE(pose2DFromOdometryMsg(odom, &pose));
}

/// Rotation about the unit axis (x, y, z) by `angle`.
geometry_msgs::Quaternion axisAngle(double x, double y, double z, double angle) {
  geometry_msgs::Quaternion q;
  q.w = std::cos(angle / 2);
  q.x = x * std::sin(angle / 2);
  q.y = y * std::sin(angle / 2);
  q.z = z * std::sin(angle / 2);
  return q;
}

TEST(ImuConversion, TheRateIsRotatedIntoTheBaseFrame) {
  sensor_msgs::Imu imu;
  imu.angular_velocity.x = 0.1;
  imu.angular_velocity.y = 0.2;
  imu.angular_velocity.z = 0.7;
  double rate = 0.0;
  std::string error;
  ASSERT_TRUE(imuValueFromMsg(imu, quaternionFromYaw(1.0), false, &rate, &error)) << error;
  EXPECT_NEAR(rate, 0.7, 1e-12) << "a yawed mount leaves the yaw rate";
  // Upside down (rolled by pi about x): the IMU's z points down, so its rate is the base's negated.
  ASSERT_TRUE(imuValueFromMsg(imu, axisAngle(1, 0, 0, M_PI), false, &rate, &error));
  EXPECT_NEAR(rate, -0.7, 1e-12);
  // Mounted on its side (pitched by -pi/2 about y: its x axis points up): the base's yaw rate is its x.
  ASSERT_TRUE(imuValueFromMsg(imu, axisAngle(0, 1, 0, -M_PI / 2), false, &rate, &error));
  EXPECT_NEAR(rate, 0.1, 1e-12);
}

TEST(ImuConversion, TheOrientationGivesTheBaseYaw) {
  sensor_msgs::Imu imu;
  double yaw = 0.0;
  std::string error;
  imu.orientation = quaternionFromYaw(2.5);
  // An IMU yawed by 0.5 rad on the base: the base's yaw is 2.0.
  ASSERT_TRUE(imuValueFromMsg(imu, quaternionFromYaw(0.5), true, &yaw, &error)) << error;
  EXPECT_NEAR(yaw, 2.0, 1e-12);
  // Upside down: the IMU's orientation is the base's rolled by pi; the base's yaw comes back.
  Eigen::Quaterniond base(Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond mount(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond sensor = base * mount;
  imu.orientation.w = sensor.w();
  imu.orientation.x = sensor.x();
  imu.orientation.y = sensor.y();
  imu.orientation.z = sensor.z();
  ASSERT_TRUE(imuValueFromMsg(imu, axisAngle(1, 0, 0, M_PI), true, &yaw, &error));
  EXPECT_NEAR(yaw, -1.2, 1e-12);
}

TEST(ImuConversion, MissingAndNonFiniteDataAreRefusedWithAReason) {
  sensor_msgs::Imu imu;
  double value = 0.0;
  std::string error;
  imu.angular_velocity_covariance[0] = -1.0;
  EXPECT_FALSE(imuValueFromMsg(imu, quaternionFromYaw(0.0), false, &value, &error));
  EXPECT_NE(error.find("no angular velocity"), std::string::npos) << error;
  imu.angular_velocity_covariance[0] = 0.0;
  imu.angular_velocity.z = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(imuValueFromMsg(imu, quaternionFromYaw(0.0), false, &value, &error));
  EXPECT_NE(error.find("not finite"), std::string::npos) << error;
  imu.orientation_covariance[0] = -1.0;
  EXPECT_FALSE(imuValueFromMsg(imu, quaternionFromYaw(0.0), true, &value, &error));
  EXPECT_NE(error.find("imu/use_orientation false"), std::string::npos) << error;
  imu.orientation_covariance[0] = 0.0;
  imu.orientation = geometry_msgs::Quaternion();
  imu.orientation.w = 0.0;
  EXPECT_FALSE(imuValueFromMsg(imu, quaternionFromYaw(0.0), true, &value, &error));
  geometry_msgs::Quaternion zero;
  zero.w = 0.0;
  imu.angular_velocity.z = 0.5;
  EXPECT_FALSE(imuValueFromMsg(imu, zero, false, &value, &error));
  EXPECT_NE(error.find("transform"), std::string::npos) << error;
}

TEST(Covariance, PlanarBlockLandsOnXYYawAndUnobservedDimensionsAreLargeButFinite) {
  Eigen::Matrix3d cov;
  cov << 0.04, 0.01, 0.002,  //
      0.01, 0.09, -0.003,    //
      0.002, -0.003, 0.0025;
  const boost::array<double, 36> out = covariance6x6FromPlanar(cov);
  EXPECT_DOUBLE_EQ(out[0 * 6 + 0], 0.04);
  EXPECT_DOUBLE_EQ(out[0 * 6 + 1], 0.01);
  EXPECT_DOUBLE_EQ(out[1 * 6 + 0], 0.01);
  EXPECT_DOUBLE_EQ(out[1 * 6 + 1], 0.09);
  EXPECT_DOUBLE_EQ(out[0 * 6 + 5], 0.002);
  EXPECT_DOUBLE_EQ(out[5 * 6 + 1], -0.003);
  EXPECT_DOUBLE_EQ(out[5 * 6 + 5], 0.0025);
  for (int i : {2, 3, 4}) {
    EXPECT_DOUBLE_EQ(out[i * 6 + i], kUnobservedVariance);
    for (int j = 0; j < 6; ++j) {
      if (j != i) {
        EXPECT_EQ(out[i * 6 + j], 0.0);
      }
    }
  }
}

TEST(Covariance, NonFiniteEntriesAreReplacedAndTheResultIsSymmetric) {
  Eigen::Matrix3d cov;
  cov << kNaN, 0.01, kInf,  //
      0.02, 0.09, 0.0,      //
      -kInf, 0.0, kNaN;
  const boost::array<double, 36> out = covariance6x6FromPlanar(cov);
  for (double v : out) EXPECT_TRUE(std::isfinite(v));
  EXPECT_DOUBLE_EQ(out[0], kUnobservedVariance);
  EXPECT_DOUBLE_EQ(out[5 * 6 + 5], kUnobservedVariance);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) EXPECT_DOUBLE_EQ(out[r * 6 + c], out[c * 6 + r]);
  }
  EXPECT_DOUBLE_EQ(out[0 * 6 + 1], 0.015);  // symmetrised
  // A bad unobserved variance falls back to the default instead of producing NaN.
  const boost::array<double, 36> fallback = covariance6x6FromPlanar(Eigen::Matrix3d::Identity(), kNaN);
  EXPECT_DOUBLE_EQ(fallback[2 * 6 + 2], kUnobservedVariance);
}

TEST(FrameIds, LeadingSlashesAreStripped) {
  EXPECT_EQ(stripLeadingSlash("/laser"), "laser");
  EXPECT_EQ(stripLeadingSlash("//base_link"), "base_link");
  EXPECT_EQ(stripLeadingSlash("odom"), "odom");
  EXPECT_EQ(stripLeadingSlash("/"), "");
  EXPECT_EQ(stripLeadingSlash(""), "");
  const std::string frame_id = "//laser";
  const std::string_view view = withoutLeadingSlash(frame_id);
  EXPECT_EQ(view, "laser");
  EXPECT_EQ(view.data(), frame_id.data() + 2) << "a view into the frame id, not a copy";
  EXPECT_EQ(withoutLeadingSlash("/"), "");
}

geometry_msgs::PoseWithCovarianceStamped setPoseMsg(const std::string& frame) {
  geometry_msgs::PoseWithCovarianceStamped msg;
  msg.header.frame_id = frame;
  msg.header.stamp = ros::Time(12.5);
  msg.pose.pose.position.x = 1.5;
  msg.pose.pose.position.y = -2.0;
  msg.pose.pose.position.z = 0.3;                      // the planar part is taken
  msg.pose.pose.orientation.z = 2.0 * std::sin(0.25);  // yaw 0.5, twice the unit length
  msg.pose.pose.orientation.w = 2.0 * std::cos(0.25);
  msg.pose.covariance[0] = 0.25;
  msg.pose.covariance[1] = msg.pose.covariance[6] = 0.01;
  msg.pose.covariance[7] = 0.36;
  msg.pose.covariance[35] = 0.07;
  msg.pose.covariance[5] = msg.pose.covariance[30] = 0.002;
  msg.pose.covariance[14] = 99.0;  // z: not planar, ignored
  return msg;
}

TEST(PoseRequest, APoseInOdomFrameGivesThePlanarPoseAndCovariance) {
  PoseRequest request;
  std::string error;
  ASSERT_TRUE(poseRequestFromMsg(setPoseMsg("/odom"), "odom", &request, &error)) << error;
  EXPECT_DOUBLE_EQ(request.stamp, 12.5);
  EXPECT_DOUBLE_EQ(request.pose.x, 1.5);
  EXPECT_DOUBLE_EQ(request.pose.y, -2.0);
  EXPECT_NEAR(request.pose.theta, 0.5, 1e-12);
  Eigen::Matrix3d expected;
  expected << 0.25, 0.01, 0.002, 0.01, 0.36, 0.0, 0.002, 0.0, 0.07;
  EXPECT_EQ(request.covariance, expected);
  EXPECT_FALSE(request.covariance_replaced);
}

TEST(PoseRequest, AnInvalidCovarianceIsReplacedByZero) {
  for (int index : {0, 5, 35}) {
    geometry_msgs::PoseWithCovarianceStamped msg = setPoseMsg("odom");
    msg.pose.covariance[index] = index == 0 ? -1.0 : kNaN;  // negative variance, asymmetric, NaN
    PoseRequest request;
    std::string error;
    ASSERT_TRUE(poseRequestFromMsg(msg, "odom", &request, &error)) << error;
    EXPECT_TRUE(request.covariance_replaced) << index;
    EXPECT_EQ(request.covariance, Eigen::Matrix3d::Zero()) << index;
    EXPECT_DOUBLE_EQ(request.pose.x, 1.5);
  }
}

TEST(PoseRequest, WrongFrameNonFiniteValuesAndDegenerateQuaternionsAreRefused) {
  PoseRequest request;
  std::string error;
  EXPECT_FALSE(poseRequestFromMsg(setPoseMsg("map"), "odom", &request, &error));
  EXPECT_EQ(error, "the pose is in frame \"map\", not in odom_frame \"odom\"");
  EXPECT_FALSE(poseRequestFromMsg(setPoseMsg(""), "odom", &request, &error));
  EXPECT_NE(error.find("not in odom_frame"), std::string::npos);
  geometry_msgs::PoseWithCovarianceStamped msg = setPoseMsg("odom");
  msg.pose.pose.position.y = kInf;
  EXPECT_FALSE(poseRequestFromMsg(msg, "odom", &request, &error));
  EXPECT_EQ(error, "the position is not finite");
  msg = setPoseMsg("odom");
  msg.pose.pose.orientation.x = kNaN;
  EXPECT_FALSE(poseRequestFromMsg(msg, "odom", &request, &error));
  EXPECT_EQ(error, "the orientation is not finite");
  msg = setPoseMsg("odom");
  msg.pose.pose.orientation = geometry_msgs::Quaternion();
  msg.pose.pose.orientation.w = 0.0;
  EXPECT_FALSE(poseRequestFromMsg(msg, "odom", &request, &error));
  EXPECT_NE(error.find("cannot be normalised"), std::string::npos) << error;
  msg.pose.pose.orientation.z = 1e200;
  msg.pose.pose.orientation.w = 1e200;
  EXPECT_FALSE(poseRequestFromMsg(msg, "odom", &request, &error));
  EXPECT_NE(error.find("cannot be normalised"), std::string::npos) << error;
}

}  // namespace
}  // namespace hglasm_odometry
