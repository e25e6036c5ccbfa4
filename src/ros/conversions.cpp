#include "hglasm_odometry/ros/conversions.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <sensor_msgs/point_cloud2_iterator.h>

namespace hglasm_odometry {
namespace {

double finiteOr(double value, double fallback) { return std::isfinite(value) ? value : fallback; }

std::uint32_t nonNegative(int count) { return static_cast<std::uint32_t>(std::max(0, count)); }

/// An arrow marker at `pose`, 0.3 m long, of colour (r, g, b).
visualization_msgs::Marker arrowMarker(const std_msgs::Header& header, int id, const hglasm::Pose2D& pose,
                                       float r, float g, float b) {
  visualization_msgs::Marker marker;
  marker.header = header;
  marker.ns = "ga_estimate";
  marker.id = id;
  marker.type = visualization_msgs::Marker::ARROW;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose = poseMsgFromPose2D(pose);
  marker.scale.x = 0.3;
  marker.scale.y = 0.04;
  marker.scale.z = 0.04;
  marker.color.r = r;
  marker.color.g = g;
  marker.color.b = b;
  marker.color.a = 1.0f;
  return marker;
}

/// Match's fields that say what happened to the scan and how it was searched.
void setMatchState(const hglasm::TrackerUpdate& update, Match* match) {
  const hglasm::TrackerDiagnostics& d = update.diagnostics;
  match->prediction_source = toMsg(d.prediction);
  match->rotation_from_imu = d.rotation_from_imu;
  match->imu_bias = finiteFloat(d.learned.imu_bias);
  match->status = update.stale ? static_cast<uint8_t>(Match::STATUS_STALE) : toMsg(d.match.status);
  match->status_text = update.stale ? "stale" : hglasm::toString(d.match.status);
  match->jump_rejected = d.jump_rejected;
  match->leap_deferred = d.leap_deferred;
  match->prediction_doubted = d.prediction_doubted;
  match->leap = update.leap;
  match->leap_probability = finiteFloat(d.leap_probability);
  match->map_keyframes = nonNegative(d.map_keyframes);
  match->search_box.x = d.search.box.half_x;
  match->search_box.y = d.search.box.half_y;
  match->search_box.theta = d.search.box.half_theta;
  match->search_population = nonNegative(d.search.population);
  match->prior_mahalanobis = finiteFloat(d.prior_mahalanobis);
  match->noise_scale_xy = finiteFloat(d.learned.wheel_noise.xy);
  match->noise_scale_theta = finiteFloat(d.learned.wheel_noise.theta);
  match->wheel_turn_scale = finiteFloat(d.learned.wheel_turn_scale);
  for (int i = 0; i < 2; ++i) match->laser_offset[i] = finiteFloat(d.learned.laser_offset[i]);
  match->degeneracy = finiteFloat(d.degeneracy);
  match->weakest_direction.x = finiteFloat(d.weakest_direction.x());
  match->weakest_direction.y = finiteFloat(d.weakest_direction.y());
  match->weakest_direction.theta = finiteFloat(d.weakest_direction.z());
  for (int j = 0; j < 3; ++j) match->scan_noise_scale[j] = finiteFloat(d.learned.scan_noise[j]);
  match->deskewed = d.deskewed;
  match->mbicp_status = toMsg(d.match.mbicp_status);
  match->matched = update.matched;
  match->fallback = update.fallback;
  match->new_keyframe = update.new_keyframe;
  match->reset = update.reset;
  match->reanchored = d.reanchored;
  match->odometry_time_offset = finiteFloat(d.odometry_time_offset);
  match->odometry_time_offset_estimate = finiteFloat(d.odometry_time_offset_estimate);
  match->keyframe_id = nonNegative(update.keyframe_id);
}

}  // namespace

hglasm::RangeScan rangeScanFromMsg(const sensor_msgs::LaserScan& msg) {
  hglasm::RangeScan scan;
  rangeScanFromMsg(msg, &scan);
  return scan;
}

void rangeScanFromMsg(const sensor_msgs::LaserScan& msg, hglasm::RangeScan* scan) {
  scan->ranges.assign(msg.ranges.begin(), msg.ranges.end());
  scan->angle_min = msg.angle_min;
  scan->angle_increment = msg.angle_increment;
  scan->time_increment = finiteOr(msg.time_increment, 0.0);
  const double range_min = msg.range_min;
  const double range_max = msg.range_max;
  scan->range_min = (std::isfinite(range_min) && range_min > 0.0) ? range_min : 0.0;
  scan->range_max =
      (std::isfinite(range_max) && range_max > 0.0) ? range_max : std::numeric_limits<double>::infinity();
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

namespace {

/// A normalised Eigen quaternion; false for a non-finite or (nearly) zero-length one.
bool toUnitQuaternion(const geometry_msgs::Quaternion& q, Eigen::Quaterniond* out) {
  const Eigen::Quaterniond quaternion(q.w, q.x, q.y, q.z);
  const double norm = quaternion.norm();
  if (!std::isfinite(norm) || norm < 1e-6) return false;
  *out = quaternion.normalized();
  return true;
}

}  // namespace

bool imuValueFromMsg(const sensor_msgs::Imu& msg, const geometry_msgs::Quaternion& base_from_imu,
                     bool use_orientation, double* value, std::string* error) {
  Eigen::Quaterniond mount;
  if (!toUnitQuaternion(base_from_imu, &mount)) {
    *error = "the transform base_frame -> IMU frame has no valid rotation";
    return false;
  }
  if (use_orientation) {
    if (msg.orientation_covariance[0] == -1.0) {
      *error =
          "the IMU publishes no orientation (orientation_covariance[0] = -1); set imu/use_orientation false";
      return false;
    }
    Eigen::Quaterniond orientation;
    if (!toUnitQuaternion(msg.orientation, &orientation)) {
      *error = "the IMU's orientation is not finite or has zero length";
      return false;
    }
    const Eigen::Quaterniond base = orientation * mount.inverse();  // the base's rotation in the world
    *value = std::atan2(2.0 * (base.w() * base.z() + base.x() * base.y()),
                        1.0 - 2.0 * (base.y() * base.y() + base.z() * base.z()));
    return true;
  }
  if (msg.angular_velocity_covariance[0] == -1.0) {
    *error = "the IMU publishes no angular velocity (angular_velocity_covariance[0] = -1)";
    return false;
  }
  const Eigen::Vector3d rate(msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z);
  if (!rate.allFinite()) {
    *error = "the IMU's angular velocity is not finite";
    return false;
  }
  *value = (mount * rate).z();
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

bool poseRequestFromMsg(const geometry_msgs::PoseWithCovarianceStamped& msg, const std::string& odom_frame,
                        PoseRequest* request, std::string* error) {
  const std::string frame = stripLeadingSlash(msg.header.frame_id);
  if (frame != odom_frame) {
    *error = "the pose is in frame \"" + frame + "\", not in odom_frame \"" + odom_frame + "\"";
    return false;
  }
  const geometry_msgs::Pose& pose = msg.pose.pose;
  const auto& q = pose.orientation;
  if (!std::isfinite(pose.position.x) || !std::isfinite(pose.position.y) || !std::isfinite(pose.position.z)) {
    *error = "the position is not finite";
    return false;
  }
  if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w)) {
    *error = "the orientation is not finite";
    return false;
  }
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!(norm >= 1e-6) || !std::isfinite(norm)) {
    *error = "the orientation quaternion cannot be normalised (length " + std::to_string(norm) + ")";
    return false;
  }
  request->stamp = msg.header.stamp.toSec();
  request->pose = hglasm::Pose2D(pose.position.x, pose.position.y, yawFromQuaternion(q));
  // Planar index (x, y, theta) <- 6D index (x, y, yaw).
  constexpr int kIndex[3] = {0, 1, 5};
  Eigen::Matrix3d covariance;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) covariance(r, c) = msg.pose.covariance[6 * kIndex[r] + kIndex[c]];
  }
  request->covariance_replaced = !hglasm::isValidPoseCovariance(covariance);
  request->covariance = request->covariance_replaced ? Eigen::Matrix3d::Zero() : covariance;
  return true;
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
  return std::string(withoutLeadingSlash(frame_id));
}

std::string_view withoutLeadingSlash(std::string_view frame_id) {
  const auto first = frame_id.find_first_not_of('/');
  return first == std::string_view::npos ? std::string_view() : frame_id.substr(first);
}

float finiteFloat(double value) { return std::isfinite(value) ? static_cast<float>(value) : 0.0f; }

std::uint8_t toMsg(hglasm::MatchStatus status) {
  switch (status) {
    case hglasm::MatchStatus::kOk:
      return Match::STATUS_OK;
    case hglasm::MatchStatus::kNoReference:
      return Match::STATUS_NO_REFERENCE;
    case hglasm::MatchStatus::kTooFewPoints:
      return Match::STATUS_TOO_FEW_POINTS;
    case hglasm::MatchStatus::kLowFitness:
      return Match::STATUS_LOW_FITNESS;
    case hglasm::MatchStatus::kMbicpFailed:
      return Match::STATUS_MBICP_FAILED;
    case hglasm::MatchStatus::kMbicpNotConverged:
      return Match::STATUS_MBICP_NOT_CONVERGED;
  }
  return Match::STATUS_NO_REFERENCE;
}

std::uint8_t toMsg(hglasm::MbicpStatus status) {
  switch (status) {
    case hglasm::MbicpStatus::kConverged:
      return Match::MBICP_CONVERGED;
    case hglasm::MbicpStatus::kMaxIterations:
      return Match::MBICP_MAX_ITERATIONS;
    case hglasm::MbicpStatus::kTooFewAssociations:
      return Match::MBICP_TOO_FEW_ASSOCIATIONS;
    case hglasm::MbicpStatus::kDegenerate:
      return Match::MBICP_DEGENERATE;
  }
  return Match::MBICP_DEGENERATE;
}

std::uint8_t toMsg(hglasm::PredictionSource source) {
  switch (source) {
    case hglasm::PredictionSource::kOdometry:
      return Match::PREDICTION_ODOMETRY;
    case hglasm::PredictionSource::kConstantVelocity:
      return Match::PREDICTION_CONSTANT_VELOCITY;
    case hglasm::PredictionSource::kNone:
      return Match::PREDICTION_NONE;
  }
  return Match::PREDICTION_NONE;
}

nav_msgs::Odometry odometryMsgFromUpdate(const hglasm::TrackerUpdate& update, const std_msgs::Header& header,
                                         const std::string& base_frame) {
  nav_msgs::Odometry odom;
  odom.header = header;
  odom.child_frame_id = base_frame;
  odom.pose.pose = poseMsgFromPose2D(update.pose);
  odom.pose.covariance = covariance6x6FromPlanar(update.pose_covariance);
  const bool velocity_finite = update.velocity.allFinite();
  odom.twist.twist.linear.x = velocity_finite ? update.velocity.x() : 0.0;
  odom.twist.twist.linear.y = velocity_finite ? update.velocity.y() : 0.0;
  odom.twist.twist.angular.z = velocity_finite ? update.velocity.z() : 0.0;
  odom.twist.covariance = covariance6x6FromPlanar(update.velocity_covariance);
  return odom;
}

Match matchMsgFromUpdate(const hglasm::PipelineUpdate& result, const std_msgs::Header& scan_header,
                         double total_ms, std::uint32_t dropped_scans) {
  const hglasm::TrackerUpdate& update = result.tracker;
  const hglasm::MatchResult& matched = update.diagnostics.match;
  Match match;
  match.header.stamp = scan_header.stamp;
  match.header.frame_id = stripLeadingSlash(scan_header.frame_id);
  setMatchState(update, &match);
  if (update.matched) {
    if (result.laser_guess) match.guess_pose = pose2DMsgFromPose2D(*result.laser_guess);
    match.prealigned_pose = pose2DMsgFromPose2D(matched.prealigned_pose);
    match.final_pose = pose2DMsgFromPose2D(matched.pose);
  }
  match.fitness_ratio = finiteFloat(update.diagnostics.fitness_ratio);
  match.prealigned_fitness = matched.prealigned_fitness;
  match.prealigned_fitness_ratio = finiteFloat(matched.prealigned_fitness_ratio);
  match.evaluations = nonNegative(matched.evaluations);
  match.iterations = nonNegative(matched.iterations);
  match.associations = nonNegative(matched.associations);
  match.rms_error = finiteFloat(matched.rms_error);
  match.valid_points = static_cast<std::uint32_t>(result.scan.size());
  match.invalid_points = nonNegative(result.scan.invalid_count);
  match.table_build_ms = finiteFloat(update.diagnostics.table_build_ms);
  match.prealign_ms = finiteFloat(matched.prealign_ms);
  match.refine_ms = finiteFloat(matched.refine_ms);
  match.total_ms = finiteFloat(total_ms);
  match.dropped_scans = dropped_scans;
  return match;
}

visualization_msgs::MarkerArray populationMarkers(const std_msgs::Header& header,
                                                  const std::vector<hglasm::Pose2D>& population,
                                                  const hglasm::Pose2D& estimate,
                                                  const hglasm::Pose2D& guess) {
  // Each individual as a short heading segment from its position (one LINE_LIST: cheap to send and draw).
  visualization_msgs::Marker individuals;
  individuals.header = header;
  individuals.ns = "ga_population";
  individuals.id = 0;
  individuals.type = visualization_msgs::Marker::LINE_LIST;
  individuals.action = visualization_msgs::Marker::ADD;
  individuals.pose.orientation.w = 1.0;
  individuals.scale.x = 0.01;
  individuals.color.r = 1.0f;
  individuals.color.g = 0.6f;
  individuals.color.a = 0.8f;
  constexpr double kHeadingLength = 0.08;
  for (const hglasm::Pose2D& pose : population) {
    if (!pose.isFinite()) continue;
    geometry_msgs::Point from, to;
    from.x = pose.x;
    from.y = pose.y;
    to.x = pose.x + kHeadingLength * std::cos(pose.theta);
    to.y = pose.y + kHeadingLength * std::sin(pose.theta);
    individuals.points.push_back(from);
    individuals.points.push_back(to);
  }
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(std::move(individuals));
  markers.markers.push_back(arrowMarker(header, 1, estimate, 0.1f, 0.9f, 0.1f));
  markers.markers.push_back(arrowMarker(header, 2, guess, 0.2f, 0.4f, 1.0f));
  return markers;
}

sensor_msgs::PointCloud2 pointCloudMsgFromPoints(const std_msgs::Header& header, const hglasm::Pose2D& frame,
                                                 const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2f> moved;
  moved.reserve(points.size());
  if (frame.isFinite()) {
    for (const Eigen::Vector2d& point : points) {
      const Eigen::Vector2f p = (frame * point).cast<float>();
      if (p.allFinite()) moved.push_back(p);
    }
  }
  sensor_msgs::PointCloud2 cloud;
  cloud.header = header;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2Fields(3, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1,
                                sensor_msgs::PointField::FLOAT32, "z", 1, sensor_msgs::PointField::FLOAT32);
  modifier.resize(moved.size());  // height 1, width = size: one unordered row
  cloud.is_dense = true;
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  for (const Eigen::Vector2f& p : moved) {
    *x = p.x();
    *y = p.y();
    *z = 0.0f;
    ++x;
    ++y;
    ++z;
  }
  return cloud;
}

}  // namespace hglasm_odometry
