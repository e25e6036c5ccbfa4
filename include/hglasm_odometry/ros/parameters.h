// Every parameter of the laser odometry, read and validated into a typed struct. The core modules declare
// their own parameters beside their options (visitOptions, core/parameter_source.h); this layer adds the
// node's (frames, topics, queue, diagnostics), composes them and applies the layers below.
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
#include "hglasm_odometry/core/parameter_source.h"
#include "hglasm_odometry/ros/diagnostics.h"  // DiagnosticsOptions

namespace hglasm_odometry {

/// Continuing from a given pose: the ~set_pose service is always offered; a topic is optional.
struct SetPoseOptions {
  /// Also take geometry_msgs/PoseWithCovarianceStamped on `topic` (as the service takes them).
  bool topic_enabled = false;
  /// Relative names resolve in the private namespace (~set_pose); "/initialpose" takes rviz's estimates.
  std::string topic = "set_pose";
};

/// A frame id: a leading slash is dropped (tf2 rejects it). Never fails (an empty frame fails later).
std::string normalizeFrame(std::string* frame);
/// "" for a valid relative or absolute graph resource name (not a private "~" one), else what it must be.
std::string checkTopic(std::string* topic);

template <typename Visitor>
void visitOptions(Visitor& visitor, SetPoseOptions* options) {
  visitor.boolean("set_pose/topic_enabled", &options->topic_enabled);
  visitor.text("set_pose/topic", &options->topic, checkTopic);
}

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

/// Every option except ~preset itself (which selects the starting point), each at its parameter path with
/// its valid range: read from the ~presets/<name> subtree and from the top level alike, or written.
template <typename Visitor>
void visitOptions(Visitor& visitor, LaserOdometryOptions* options) {
  visitor.text("odom_frame", &options->odom_frame, normalizeFrame);
  visitor.text("base_frame", &options->base_frame, normalizeFrame);
  visitor.boolean("publish_tf", &options->publish_tf);
  visitor.integer("path_length", &options->path_length, 0, 1000000);
  visitor.integer("queue_size", &options->queue_size, 1, 10000);
  visitor.boolean("publish_population", &options->publish_population);
  visitor.positiveNumber("tf_warn_period", &options->tf_warn_period);
  visitor.number("odometry/wait", &options->odometry_wait, 0.0, 10.0);
  visitOptions(visitor, &options->set_pose);
  hglasm::visitOptions(visitor, &options->tracker);
  visitOptions(visitor, &options->diagnostics);
}

/// The parameter server's values (an XmlRpc struct, as getParam returns a namespace) as a ParameterSource.
class XmlRpcParameterSource : public hglasm::ParameterSource {
 public:
  explicit XmlRpcParameterSource(const XmlRpc::XmlRpcValue& root) : root_(root) {}
  bool find(const std::string& path, hglasm::ParameterValue* value) const override;
  std::vector<std::string> leafPaths() const override;

 private:
  const XmlRpc::XmlRpcValue& root_;
};

/// Loads options from the private namespace's parameters, in the order of precedence above: the one loader
/// of the nodelet, the node and the offline tools (a YAML file). On failure returns false, sets *error to
/// one line naming the parameter, and leaves *options unspecified.
bool loadOptions(const hglasm::ParameterSource& private_params, LaserOdometryOptions* options,
                 std::string* error, std::vector<std::string>* warnings = nullptr);

/// The same from one XmlRpc struct (as returned by getParam on the namespace). Needs no ROS master, which
/// is what the unit tests use.
bool loadOptions(const XmlRpc::XmlRpcValue& private_params, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings = nullptr);

/// Reads the whole private namespace of `private_nh` and calls the function above.
bool loadOptions(const ros::NodeHandle& private_nh, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings = nullptr);

/// Every option at the parameter path loadOptions reads it from (~preset and ~presets aside): loading the
/// result gives `options` back. For comparing a configuration with the shipped YAML, or printing it.
XmlRpc::XmlRpcValue toParams(const LaserOdometryOptions& options);
/// The same as a ParameterTree.
hglasm::ParameterTree toParameterTree(const LaserOdometryOptions& options);

/// One line for the log: preset, box, GA size, frames.
std::string summarize(const LaserOdometryOptions& options);

}  // namespace hglasm_odometry
