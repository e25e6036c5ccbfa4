#include "hglasm_odometry/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hglasm_odometry {
namespace {

double finiteOr(double value, double fallback) { return std::isfinite(value) ? value : fallback; }

}  // namespace

hglasm::RangeScan rangeScanFromMsg(const sensor_msgs::LaserScan& msg) {
  hglasm::RangeScan scan;
  scan.ranges = msg.ranges;
  scan.angle_min = msg.angle_min;
  scan.angle_increment = msg.angle_increment;
  scan.time_increment = finiteOr(msg.time_increment, 0.0);
  const double range_min = msg.range_min;
  const double range_max = msg.range_max;
  scan.range_min = (std::isfinite(range_min) && range_min > 0.0) ? range_min : 0.0;
  scan.range_max =
      (std::isfinite(range_max) && range_max > 0.0) ? range_max : std::numeric_limits<double>::infinity();
  return scan;
}

bool laserMountFromTransform(const geometry_msgs::Transform& transform, LaserMount* mount,
                             std::string* error) {
  const auto& t = transform.translation;
  const auto& q = transform.rotation;
  if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z) || !std::isfinite(q.x) ||
      !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w)) {
    if (error) *error = "the transform is not finite";
    return false;
  }
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (norm < 1e-9) {
    if (error) *error = "the rotation quaternion has zero length";
    return false;
  }
  const double x = q.x / norm, y = q.y / norm, z = q.z / norm, w = q.w / norm;
  // Rotation matrix entries needed: the 2x2 xy block and the z component of the laser's z axis.
  const double r00 = 1.0 - 2.0 * (y * y + z * z);
  const double r01 = 2.0 * (x * y - z * w);
  const double r10 = 2.0 * (x * y + z * w);
  const double r11 = 1.0 - 2.0 * (x * x + z * z);
  const double r22 = 1.0 - 2.0 * (x * x + y * y);

  const bool upside_down = r22 < 0.0;
  // Seen from above, an upside-down laser's scan is mirrored: use M = R2 * diag(1, -1) with mirrored
  // scans (R2 * p = M * diag(1, -1) * p).
  const double m00 = r00, m10 = r10;
  const double m01 = upside_down ? -r01 : r01;
  const double m11 = upside_down ? -r11 : r11;
  // Angle of the rotation closest to M (exact for a level laser, best fit for a tilted one).
  const double sin_part = m10 - m01;
  const double cos_part = m00 + m11;
  if (std::hypot(sin_part, cos_part) < 1e-6) {
    if (error) *error = "the laser's scan plane is vertical: it cannot be projected onto the ground plane";
    return false;
  }
  mount->base_to_laser = hglasm::Pose2D(t.x, t.y, std::atan2(sin_part, cos_part));
  mount->upside_down = upside_down;
  mount->tilt = std::acos(std::min(1.0, std::abs(r22)));
  return true;
}

double yawFromQuaternion(const geometry_msgs::Quaternion& q) {
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!std::isfinite(norm) || norm < 1e-12) return 0.0;
  const double x = q.x / norm, y = q.y / norm, z = q.z / norm, w = q.w / norm;
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

geometry_msgs::Quaternion quaternionFromYaw(double yaw) {
  geometry_msgs::Quaternion q;
  const double half = std::isfinite(yaw) ? 0.5 * yaw : 0.0;
  q.x = 0.0;
  q.y = 0.0;
  q.z = std::sin(half);
  q.w = std::cos(half);
  return q;
}

bool pose2DFromPoseMsg(const geometry_msgs::Pose& msg, hglasm::Pose2D* pose) {
  const auto& q = msg.orientation;
  if (!std::isfinite(msg.position.x) || !std::isfinite(msg.position.y) || !std::isfinite(q.x) ||
      !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w)) {
    return false;
  }
  *pose = hglasm::Pose2D(msg.position.x, msg.position.y, yawFromQuaternion(q));
  return true;
}

geometry_msgs::Pose poseMsgFromPose2D(const hglasm::Pose2D& pose) {
  geometry_msgs::Pose msg;
  msg.position.x = finiteOr(pose.x, 0.0);
  msg.position.y = finiteOr(pose.y, 0.0);
  msg.position.z = 0.0;
  msg.orientation = quaternionFromYaw(pose.theta);
  return msg;
}

geometry_msgs::Transform transformMsgFromPose2D(const hglasm::Pose2D& pose) {
  geometry_msgs::Transform msg;
  msg.translation.x = finiteOr(pose.x, 0.0);
  msg.translation.y = finiteOr(pose.y, 0.0);
  msg.translation.z = 0.0;
  msg.rotation = quaternionFromYaw(pose.theta);
  return msg;
}

geometry_msgs::Pose2D pose2DMsgFromPose2D(const hglasm::Pose2D& pose) {
  geometry_msgs::Pose2D msg;
  msg.x = finiteOr(pose.x, 0.0);
  msg.y = finiteOr(pose.y, 0.0);
  msg.theta = finiteOr(pose.theta, 0.0);
  return msg;
}

bool pose2DFromPose2DMsg(const geometry_msgs::Pose2D& msg, hglasm::Pose2D* pose) {
  if (!std::isfinite(msg.x) || !std::isfinite(msg.y) || !std::isfinite(msg.theta)) return false;
  *pose = hglasm::Pose2D(msg.x, msg.y, msg.theta);
  return true;
}

bool pose2DFromOdometryMsg(const nav_msgs::Odometry& msg, hglasm::Pose2D* pose) {
  return pose2DFromPoseMsg(msg.pose.pose, pose);
}

boost::array<double, 36> covariance6x6FromPlanar(const Eigen::Matrix3d& covariance,
                                                 double unobserved_variance) {
  if (!std::isfinite(unobserved_variance) || unobserved_variance <= 0.0)
    unobserved_variance = kUnobservedVariance;
  boost::array<double, 36> out;
  out.fill(0.0);
  // Planar index (x, y, theta) -> 6D index (x, y, yaw).
  constexpr int kIndex[3] = {0, 1, 5};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      double value = 0.5 * (covariance(r, c) + covariance(c, r));
      if (!std::isfinite(value)) value = (r == c) ? unobserved_variance : 0.0;
      if (r == c && value < 0.0) value = 0.0;
      out[kIndex[r] * 6 + kIndex[c]] = value;
    }
  }
  for (int unobserved : {2, 3, 4}) out[unobserved * 6 + unobserved] = unobserved_variance;
  return out;
}

std::string stripLeadingSlash(const std::string& frame_id) {
  const auto first = frame_id.find_first_not_of('/');
  return first == std::string::npos ? std::string() : frame_id.substr(first);
}

}  // namespace hglasm_odometry
