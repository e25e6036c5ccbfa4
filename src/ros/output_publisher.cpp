#include "hglasm_odometry/ros/output_publisher.h"

#include <algorithm>
#include <utility>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "hglasm_odometry/Match.h"
#include "hglasm_odometry/ros/conversions.h"

namespace hglasm_odometry {

void PathHistory::toMsg(const std_msgs::Header& header, nav_msgs::Path* path) const {
  path->header = header;
  path->poses.resize(poses_.size());
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    geometry_msgs::PoseStamped& pose = path->poses[i];
    pose.header.seq = header.seq;
    pose.header.stamp = poses_[i].stamp;
    pose.header.frame_id = header.frame_id;
    pose.pose = poseMsgFromPose2D(poses_[i].pose);
  }
}

OutputPublisher::OutputPublisher(ros::NodeHandle& private_nh, const LaserOdometryOptions& options,
                                 std::function<void()> on_local_map_subscriber)
    : odom_frame_(options.odom_frame),
      base_frame_(options.base_frame),
      publish_tf_(options.publish_tf),
      publish_population_(options.publish_population),
      path_(static_cast<std::size_t>(std::max(options.path_length, 1))) {
  odom_pub_ = private_nh.advertise<nav_msgs::Odometry>("odom", 50);
  pose_pub_ = private_nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 50);
  if (publish_tf_) {
    // What tf2_ros::TransformBroadcaster advertises (the process's node handle, /tf, queue 100); its own
    // publisher lets the message be reused.
    tf_pub_ = ros::NodeHandle().advertise<tf2_msgs::TFMessage>("/tf", 100);
    tf_msg_.transforms.resize(1);
  }
  if (options.path_length > 0) path_pub_ = private_nh.advertise<nav_msgs::Path>("path", 2);
  match_pub_ = private_nh.advertise<Match>("match", 50);
  if (publish_population_) {
    population_pub_ = private_nh.advertise<visualization_msgs::MarkerArray>("ga_population", 2);
  }
  local_map_pub_ = private_nh.advertise<sensor_msgs::PointCloud2>(
      "local_map", 2,
      [callback = std::move(on_local_map_subscriber)](const ros::SingleSubscriberPublisher&) { callback(); });
}

bool OutputPublisher::populationWanted() const {
  return publish_population_ && population_pub_.getNumSubscribers() > 0;
}

std_msgs::Header OutputPublisher::odomHeader(const ros::Time& stamp) const {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = odom_frame_;
  return header;
}

void OutputPublisher::publishEstimate(const ros::Time& stamp, const hglasm::TrackerUpdate& update) {
  const std_msgs::Header header = odomHeader(stamp);
  const bool odom_wanted = odom_pub_.getNumSubscribers() > 0;
  const bool pose_wanted = pose_pub_.getNumSubscribers() > 0;
  if (odom_wanted || pose_wanted) {
    const nav_msgs::Odometry odom = odometryMsgFromUpdate(update, header, base_frame_);
    if (odom_wanted) odom_pub_.publish(odom);
    if (pose_wanted) {
      geometry_msgs::PoseWithCovarianceStamped pose;
      pose.header = header;
      pose.pose = odom.pose;
      pose_pub_.publish(pose);
    }
  }
  if (publish_tf_) publishTransform(header, update.pose);
  if (path_pub_) publishPath(header, update.pose);
}

void OutputPublisher::publishTransform(const std_msgs::Header& header, const hglasm::Pose2D& pose) {
  if (tf_pub_.getNumSubscribers() == 0) return;
  geometry_msgs::TransformStamped& transform = tf_msg_.transforms.front();
  transform.header = header;
  transform.child_frame_id = base_frame_;
  transform.transform = transformMsgFromPose2D(pose);
  tf_pub_.publish(tf_msg_);
}

void OutputPublisher::publishPath(const std_msgs::Header& header, const hglasm::Pose2D& pose) {
  path_.add(header.stamp, pose);
  if (path_pub_.getNumSubscribers() == 0) return;
  path_.toMsg(header, &path_msg_);
  path_pub_.publish(path_msg_);
}

void OutputPublisher::publishMatch(const std_msgs::Header& scan, const hglasm::PipelineUpdate& result,
                                   double total_ms, std::uint32_t dropped_scans) {
  match_pub_.publish(matchMsgFromUpdate(result, scan, total_ms, dropped_scans));
}

void OutputPublisher::publishPopulation(const ros::Time& stamp, const hglasm::TrackerUpdate& update,
                                        const std::vector<hglasm::Pose2D>& population) {
  population_pub_.publish(
      populationMarkers(odomHeader(stamp), population, update.pose, update.diagnostics.guess));
}

void OutputPublisher::publishLocalMap(const ros::Time& stamp, const hglasm::LocalMap& map, bool resend) {
  if (!resend && local_map_sent_ && map.revision() == local_map_revision_) return;
  local_map_pub_.publish(pointCloudMsgFromPoints(odomHeader(stamp), map.frame(), map.reference().points));
  local_map_sent_ = true;
  local_map_revision_ = map.revision();
}

}  // namespace hglasm_odometry
