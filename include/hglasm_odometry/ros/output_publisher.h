// The laser odometry's outputs, one scan at a time (from the worker thread): ~odom, ~pose, tf, ~path,
// ~match, ~ga_population and ~local_map. A message is built only while its topic has a subscriber (the
// path's history is kept regardless, so a late subscriber gets it whole), in storage reused from scan to
// scan.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <std_msgs/Header.h>
#include <tf2_msgs/TFMessage.h>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/ros/parameters.h"
#include "hglasm_odometry/ros/ring_buffer.h"

namespace hglasm_odometry {

/// The poses ~path holds: the newest `length` published, each at its scan's stamp. ROS messages, no
/// roscpp (unit-tested without a master).
class PathHistory {
 public:
  explicit PathHistory(std::size_t length) : poses_(length) {}

  void add(const ros::Time& stamp, const hglasm::Pose2D& pose) { poses_.push_back({stamp, pose}); }
  void clear() { poses_.clear(); }
  std::size_t size() const { return poses_.size(); }

  /// The ~path message, oldest pose first, every pose in `header`'s frame; reuses *path's storage.
  void toMsg(const std_msgs::Header& header, nav_msgs::Path* path) const;

 private:
  struct StampedPose {
    ros::Time stamp;
    hglasm::Pose2D pose;
  };
  RingBuffer<StampedPose> poses_;
};

class OutputPublisher {
 public:
  /// Advertises in `private_nh` (tf on /tf, as tf2_ros::TransformBroadcaster does). `on_local_map_subscriber`
  /// runs on a spinner thread whenever ~local_map gets a subscriber (it is not latched: the next scan sends
  /// the map to the newcomer).
  OutputPublisher(ros::NodeHandle& private_nh, const LaserOdometryOptions& options,
                  std::function<void()> on_local_map_subscriber);

  /// publish_population, and someone subscribes to ~ga_population: the GA's population is worth collecting.
  bool populationWanted() const;
  bool matchWanted() const { return match_pub_.getNumSubscribers() > 0; }
  bool localMapWanted() const { return local_map_pub_.getNumSubscribers() > 0; }

  /// The estimate restarted (a reset, a new pose): the path starts again.
  void restartPath() { path_.clear(); }

  /// ~odom, ~pose, tf and ~path for a published estimate at `stamp`.
  void publishEstimate(const ros::Time& stamp, const hglasm::TrackerUpdate& update);
  /// ~match: `scan` the scan's header, the other arguments as matchMsgFromUpdate takes them.
  void publishMatch(const std_msgs::Header& scan, const hglasm::PipelineUpdate& result, double total_ms,
                    std::uint32_t dropped_scans);
  void publishPopulation(const ros::Time& stamp, const hglasm::TrackerUpdate& update,
                         const std::vector<hglasm::Pose2D>& population);
  /// ~local_map, when `map` changed since it was last sent, or `resend` (a subscriber connected since).
  void publishLocalMap(const ros::Time& stamp, const hglasm::LocalMap& map, bool resend);

 private:
  std_msgs::Header odomHeader(const ros::Time& stamp) const;
  void publishTransform(const std_msgs::Header& header, const hglasm::Pose2D& pose);
  void publishPath(const std_msgs::Header& header, const hglasm::Pose2D& pose);

  const std::string odom_frame_;
  const std::string base_frame_;
  const bool publish_tf_;
  const bool publish_population_;
  PathHistory path_;
  nav_msgs::Path path_msg_;     // reused: its poses' storage stays
  tf2_msgs::TFMessage tf_msg_;  // reused: one transform
  bool local_map_sent_ = false;
  std::uint64_t local_map_revision_ = 0;  // hglasm::LocalMap::revision() of the last ~local_map sent

  ros::Publisher odom_pub_;
  ros::Publisher pose_pub_;
  ros::Publisher tf_pub_;
  ros::Publisher path_pub_;
  ros::Publisher match_pub_;
  ros::Publisher population_pub_;
  ros::Publisher local_map_pub_;
};

}  // namespace hglasm_odometry
