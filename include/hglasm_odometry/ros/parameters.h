// Every parameter of the laser odometry, read and validated in one place into a typed struct.
//
// Order of precedence (later wins):
//   1. the built-in values of the preset named by ~preset (hglasm::presetOptions, small|medium|large);
//   2. ~presets/<preset>/...  (config/presets.yaml, loaded under ~presets by the launch files);
//   3. the same keys at the top level of the private namespace (config/laser_odometry.yaml, or any
//      individual override).
// A name under ~presets that is not one of the built-in presets defines a custom preset on top of
// the built-in medium one.
//
// Any wrong type, non-finite, negative or zero size, or out-of-range value fails the whole load with
// ONE message naming the parameter, e.g.
//   "parameter ~genetic/population must be a positive integer, got -5".
// Unknown keys (typos) are not errors; they are returned as warnings for the log.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "hglasm_odometry/core/odometry_tracker.h"
#include "hglasm_odometry/ros/diagnostics.h"  // DiagnosticsOptions

namespace hglasm_odometry {

/// Continuing from a given pose: the ~set_pose service is always offered; a topic is optional.
struct SetPoseOptions {
  /// Also take geometry_msgs/PoseWithCovarianceStamped on `topic` (as the service takes them).
  bool topic_enabled = false;
  /// Relative names resolve in the private namespace (~set_pose); "/initialpose" takes rviz's estimates.
  std::string topic = "set_pose";
};

struct LaserOdometryOptions {
  std::string preset = "medium";  ///< name of the preset the matcher options started from
  /// Matcher (from the preset), keyframes, failure policy, wheel odometry (use_odometry: ~use_odom, also
  /// whether `odom` is subscribed).
  hglasm::TrackerOptions tracker;
  std::string odom_frame = "odom";       ///< parent frame of the published pose and tf
  std::string base_frame = "base_link";  ///< frame whose motion is estimated (child frame)
  bool publish_tf = true;                ///< broadcast odom_frame -> base_frame
  int path_length = 1000;                ///< poses kept on ~path; 0 disables ~path
  int queue_size = 5;                    ///< scans waiting to be processed; the oldest is dropped beyond
  bool publish_population = false;       ///< ~ga_population markers (costs a copy of the population)
  double tf_warn_period = 5.0;           ///< seconds between "waiting for tf" messages
  /// Wall seconds a scan may wait for wheel odometry stamped at or after it (so the prediction is
  /// interpolated, not held from an older sample). Not waited for when odometry has stopped; 0 = never.
  double odometry_wait = 0.25;
  SetPoseOptions set_pose;
  DiagnosticsOptions diagnostics;
};

/// Loads options from the private namespace as one XmlRpc struct (as returned by getParam on the
/// namespace). Needs no ROS master, which is what the unit tests use. On failure returns false,
/// sets *error to one line naming the parameter, and leaves *options unspecified.
bool loadOptions(const XmlRpc::XmlRpcValue& private_params, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings = nullptr);

/// Reads the whole private namespace of `private_nh` and calls the function above.
bool loadOptions(const ros::NodeHandle& private_nh, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings = nullptr);

/// Every option at the parameter path loadOptions reads it from (~preset and ~presets aside): loading the
/// result gives `options` back. For comparing a configuration with the shipped YAML, or printing it.
XmlRpc::XmlRpcValue toParams(const LaserOdometryOptions& options);

/// One line for the log: preset, box, GA size, frames.
std::string summarize(const LaserOdometryOptions& options);

}  // namespace hglasm_odometry
