// Conversions between ROS 1 messages and the ROS-free core types, the node's outgoing messages and
// markers included. All functions are NaN/inf-safe: they never throw and never put a non-finite number into
// an outgoing message.
#pragma once

#include <Eigen/Core>
#include <boost/array.hpp>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Pose2D.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include "hglasm_odometry/Match.h"
#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm_odometry {

/// Variance given to the unobserved dimensions (z, roll, pitch) of a planar estimate: large but
/// finite, so consumers that invert the matrix (robot_localization) still can.
constexpr double kUnobservedVariance = 1e6;

/// The polar fields of a LaserScan. Ranges are copied unchanged (the core drops NaN/inf/out-of-limit
/// ranges per REP-117). A non-finite or negative range_min becomes 0 and a non-finite or non-positive
/// range_max becomes +inf, so one bad header field does not invalidate every beam.
hglasm::RangeScan rangeScanFromMsg(const sensor_msgs::LaserScan& msg);
/// The same into *scan, reusing its storage: nothing allocated per scan once it has held the longest one.
void rangeScanFromMsg(const sensor_msgs::LaserScan& msg, hglasm::RangeScan* scan);

/// The planar part of base -> laser.
struct LaserMount {
  /// Pose of the laser in the base frame, projected onto the base's xy plane (after mirroring).
  hglasm::Pose2D base_to_laser;
  /// The laser's z axis points down: seen from above its scan is a mirror image, so scans must be
  /// converted with ScanConversionOptions::mirror = true before base_to_laser applies.
  bool upside_down = false;
  /// Angle between the laser's z axis and the base's z (or -z) axis, radians. Large tilts make the
  /// planar projection inexact; callers warn about it.
  double tilt = 0.0;
};

/// Projects a 3D base -> laser transform onto the plane. The 2x2 block R2 of the rotation is a rotation
/// for an upright laser and a reflection for an upside-down one (R2 ~ Rot * diag(1, -1)): then the
/// proper rotation R2 * diag(1, -1) is used together with mirrored scans. False (with *error) if the
/// transform is not finite or its rotation is degenerate (laser plane vertical).
bool laserMountFromTransform(const geometry_msgs::Transform& transform, LaserMount* mount,
                             std::string* error);

/// What the odometry takes from a sensor_msgs/Imu: the base's yaw rate (rad/s), or with `use_orientation`
/// its yaw (rad) in the IMU's world frame. `base_from_imu` is the IMU frame's rotation in base_frame (tf).
/// The angular velocity is rotated into the base frame (a tilted or upside-down IMU) and its z taken; the
/// orientation is composed with base_from_imu's inverse. False, with *error saying why, when the message
/// says it has no such data (covariance[0] == -1, REP-145), a value is not finite, or a quaternion cannot
/// be normalised.
bool imuValueFromMsg(const sensor_msgs::Imu& msg, const geometry_msgs::Quaternion& base_from_imu,
                     bool use_orientation, double* value, std::string* error);

/// Yaw of a quaternion (normalised first); 0 for a zero-length or non-finite quaternion.
double yawFromQuaternion(const geometry_msgs::Quaternion& q);
/// Rotation about z; identity for a non-finite yaw.
geometry_msgs::Quaternion quaternionFromYaw(double yaw);

/// Planar part of a 3D pose. False (and *pose untouched) if the pose is not finite.
bool pose2DFromPoseMsg(const geometry_msgs::Pose& msg, hglasm::Pose2D* pose);
/// A pose in the z = 0 plane; non-finite components become 0.
geometry_msgs::Pose poseMsgFromPose2D(const hglasm::Pose2D& pose);
geometry_msgs::Transform transformMsgFromPose2D(const hglasm::Pose2D& pose);

geometry_msgs::Pose2D pose2DMsgFromPose2D(const hglasm::Pose2D& pose);
/// False (and *pose untouched) if the message is not finite.
bool pose2DFromPose2DMsg(const geometry_msgs::Pose2D& msg, hglasm::Pose2D* pose);

/// Pose of child_frame_id in header.frame_id. False if the pose is not finite.
bool pose2DFromOdometryMsg(const nav_msgs::Odometry& msg, hglasm::Pose2D* pose);

/// (x, y, theta) covariance -> row-major 6x6 (x, y, z, roll, pitch, yaw). Non-finite entries are
/// replaced (diagonal: `unobserved_variance`, off-diagonal: 0) and the matrix is symmetrised; the
/// z/roll/pitch diagonal gets `unobserved_variance`.
boost::array<double, 36> covariance6x6FromPlanar(const Eigen::Matrix3d& covariance,
                                                 double unobserved_variance = kUnobservedVariance);

/// A request to continue from a given pose (~set_pose): the pose of the base in the odometry frame.
struct PoseRequest {
  double stamp = 0.0;  ///< seconds; 0: the message carried none (callers use now)
  hglasm::Pose2D pose;
  /// x, y, yaw block of the message's covariance, or zero (the pose exact) when that is not a valid
  /// covariance (hglasm::isValidPoseCovariance).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool covariance_replaced = false;  ///< the message's covariance was invalid and replaced by zero
};

/// A set-pose request from a pose of the base in `odom_frame`. False, with *error saying why, if
/// header.frame_id (without a leading slash) is not `odom_frame`, the position or the orientation is not
/// finite, or the quaternion cannot be normalised (length below 1e-6).
bool poseRequestFromMsg(const geometry_msgs::PoseWithCovarianceStamped& msg, const std::string& odom_frame,
                        PoseRequest* request, std::string* error);

/// "/laser" -> "laser": tf2 rejects frame ids with a leading slash, old bags (ccny) still carry them.
std::string stripLeadingSlash(const std::string& frame_id);
/// The same without a copy (a view into `frame_id`), for comparing the frame of every message.
std::string_view withoutLeadingSlash(std::string_view frame_id);

/// A float for a message field: 0 for a non-finite value.
float finiteFloat(double value);

/// Match.msg's constants for the core's enums.
std::uint8_t toMsg(hglasm::MatchStatus status);
std::uint8_t toMsg(hglasm::MbicpStatus status);
std::uint8_t toMsg(hglasm::PredictionSource source);

/// ~odom for a published estimate: the base's pose in `header`'s frame (its stamp too) with its covariance,
/// and the velocity in the base frame with its covariance (0 if any component is not finite).
nav_msgs::Odometry odometryMsgFromUpdate(const hglasm::TrackerUpdate& update, const std_msgs::Header& header,
                                         const std::string& base_frame);

/// ~match for one scan: `scan_header` the scan's (its frame id without a leading slash goes in),
/// `total_ms` the wall time spent on it, `dropped_scans` the input queue's count so far. Counts below 0
/// become 0; the poses stay 0 when no match was attempted.
Match matchMsgFromUpdate(const hglasm::PipelineUpdate& result, const std_msgs::Header& scan_header,
                         double total_ms, std::uint32_t dropped_scans);

/// ~ga_population: each finite individual of `population` as a heading segment from its position (one
/// LINE_LIST, id 0, namespace "ga_population"), and arrows for the estimate (green, id 1) and the
/// prediction the search was centred on (blue, id 2; namespace "ga_estimate"), all in `header`'s frame.
visualization_msgs::MarkerArray populationMarkers(const std_msgs::Header& header,
                                                  const std::vector<hglasm::Pose2D>& population,
                                                  const hglasm::Pose2D& estimate,
                                                  const hglasm::Pose2D& guess);

/// ~local_map: `points`, given in a frame whose pose in `header`'s frame is `frame` (LocalMap::frame() and
/// reference().points), moved into `header`'s frame (its stamp too) as one unordered row of x, y, z float32
/// fields (z = 0). Points that are not finite there are left out (the cloud is dense); none if `frame`
/// is not finite.
sensor_msgs::PointCloud2 pointCloudMsgFromPoints(const std_msgs::Header& header, const hglasm::Pose2D& frame,
                                                 const std::vector<Eigen::Vector2d>& points);

}  // namespace hglasm_odometry
