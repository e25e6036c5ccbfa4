// Reads scans, wheel odometry and the base -> laser mounting from a bag with the rosbag C++ API.
#include "hglasm_odometry/tools/bag_reader.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include "hglasm_odometry/ros/conversions.h"

namespace hglasm_odometry {

namespace {

std::string withSlash(const std::string& topic) {
  return !topic.empty() && topic.front() != '/' ? "/" + topic : topic;
}

Eigen::Isometry3d isometryFromTransform(const geometry_msgs::Transform& transform) {
  Eigen::Quaterniond rotation(transform.rotation.w, transform.rotation.x, transform.rotation.y,
                              transform.rotation.z);
  if (rotation.norm() < 1e-9) rotation = Eigen::Quaterniond::Identity();  // unset quaternion
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = rotation.normalized().toRotationMatrix();
  isometry.translation() =
      Eigen::Vector3d(transform.translation.x, transform.translation.y, transform.translation.z);
  return isometry;
}

/// A transform tree: each child frame with its parent and parent -> child transform.
struct Edge {
  std::string parent;
  Eigen::Isometry3d parent_to_child;
};
using TransformTree = std::map<std::string, Edge>;

void addTransforms(const tf2_msgs::TFMessage& message, bool overwrite, TransformTree* tree) {
  for (const auto& stamped : message.transforms) {
    const std::string child = stripLeadingSlash(stamped.child_frame_id);
    const std::string parent = stripLeadingSlash(stamped.header.frame_id);
    if (child.empty() || parent.empty() || child == parent) continue;
    if (!overwrite && tree->count(child)) continue;
    (*tree)[child] = Edge{parent, isometryFromTransform(stamped.transform)};
  }
}

/// The frames from `frame` up to the root of its tree, `frame` first.
std::vector<std::string> ancestry(const TransformTree& tree, const std::string& frame) {
  std::vector<std::string> chain = {frame};
  std::set<std::string> visited = {frame};
  for (auto it = tree.find(frame); it != tree.end() && visited.insert(it->second.parent).second;
       it = tree.find(chain.back())) {
    chain.push_back(it->second.parent);
  }
  return chain;
}

/// Transform from `ancestor` to `frame` (one of `frame`'s ancestry, or `frame` itself).
Eigen::Isometry3d ancestorToFrame(const TransformTree& tree, const std::string& ancestor,
                                  const std::string& frame) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  for (std::string current = frame; current != ancestor;) {
    const Edge& edge = tree.at(current);
    transform = edge.parent_to_child * transform;
    current = edge.parent;
  }
  return transform;
}

/// base -> laser from the tree, if both frames are connected. Composed only up to their lowest common
/// ancestor, as tf2 does: a detour through the root (the wheel odometry's odom -> base_link, metres from
/// the origin) added rounding, 2.7e-15 m on fr079's 0.04 m mount, so offline runs differed from the node.
bool lookupMount(const TransformTree& tree, const std::string& base, const std::string& laser,
                 Eigen::Isometry3d* base_to_laser) {
  const std::vector<std::string> laser_chain = ancestry(tree, laser);
  const std::set<std::string> laser_ancestors(laser_chain.begin(), laser_chain.end());
  for (const std::string& common : ancestry(tree, base)) {
    if (!laser_ancestors.count(common)) continue;
    *base_to_laser = ancestorToFrame(tree, common, base).inverse() * ancestorToFrame(tree, common, laser);
    return true;
  }
  return false;
}

}  // namespace

bool readBag(const std::string& path, const BagReadOptions& options, BagData* data, std::string* error) {
  *data = BagData();
  const std::string scan_topic = withSlash(options.scan_topic);
  const std::string odom_topic = withSlash(options.odom_topic);

  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& exception) {
    if (error) *error = "cannot open bag '" + path + "': " + exception.what();
    return false;
  }

  std::vector<std::string> topics = {scan_topic, "/tf_static", "/tf"};
  if (!odom_topic.empty()) topics.push_back(odom_topic);

  TransformTree static_tree, dynamic_tree;
  std::string odom_child_frame;
  std::string laser_frame;
  bool scans_complete = false;
  double last_wanted_stamp = 0.0;
  try {
    rosbag::View view(bag, rosbag::TopicQuery(topics));
    for (const rosbag::MessageInstance& message : view) {
      // With max_scans, stop a little after the last wanted scan so its odometry is bracketed.
      if (scans_complete && message.getTime().toSec() > last_wanted_stamp + 1.0) break;
      const std::string& topic = message.getTopic();
      if (topic == scan_topic) {
        if (scans_complete) continue;
        const auto scan = message.instantiate<sensor_msgs::LaserScan>();
        if (!scan) continue;
        BagScan bag_scan;
        bag_scan.stamp = scan->header.stamp.toSec();
        bag_scan.frame_id = stripLeadingSlash(scan->header.frame_id);
        bag_scan.ranges = rangeScanFromMsg(*scan);
        if (laser_frame.empty()) laser_frame = bag_scan.frame_id;
        data->scans.push_back(std::move(bag_scan));
        if (options.max_scans > 0 && data->scans.size() >= options.max_scans) {
          scans_complete = true;
          last_wanted_stamp = std::max(message.getTime().toSec(), data->scans.back().stamp);
        }
      } else if (topic == odom_topic) {
        const auto odom = message.instantiate<nav_msgs::Odometry>();
        if (!odom) continue;
        BagOdometry sample;
        sample.stamp = odom->header.stamp.toSec();
        if (!pose2DFromOdometryMsg(*odom, &sample.pose)) continue;
        if (odom_child_frame.empty()) odom_child_frame = stripLeadingSlash(odom->child_frame_id);
        data->odometry.push_back(sample);
      } else if (topic == "/tf_static" || topic == "/tf") {
        const auto tf = message.instantiate<tf2_msgs::TFMessage>();
        if (!tf) continue;
        // Latest static transform wins; from /tf keep the first of each frame (only mountings matter).
        if (topic == "/tf_static") {
          addTransforms(*tf, true, &static_tree);
        } else {
          addTransforms(*tf, false, &dynamic_tree);
        }
      }
    }
  } catch (const rosbag::BagException& exception) {
    if (error) *error = "error reading bag '" + path + "': " + exception.what();
    return false;
  }
  bag.close();

  if (data->scans.empty()) {
    if (error) *error = "bag '" + path + "' holds no sensor_msgs/LaserScan on topic '" + scan_topic + "'";
    return false;
  }

  const auto by_stamp = [](const auto& a, const auto& b) { return a.stamp < b.stamp; };
  std::stable_sort(data->scans.begin(), data->scans.end(), by_stamp);
  std::stable_sort(data->odometry.begin(), data->odometry.end(), by_stamp);

  data->base_frame = stripLeadingSlash(options.base_frame);
  if (data->base_frame.empty()) data->base_frame = odom_child_frame;
  if (data->base_frame.empty()) data->base_frame = "base_link";

  // Static transforms first; dynamic ones only fill frames /tf_static does not know.
  TransformTree tree = dynamic_tree;
  for (const auto& entry : static_tree) tree[entry.first] = entry.second;

  Eigen::Isometry3d base_to_laser = Eigen::Isometry3d::Identity();
  if (laser_frame == data->base_frame) {
    data->has_laser_mount = true;
  } else {
    data->has_laser_mount = lookupMount(tree, data->base_frame, laser_frame, &base_to_laser);
  }
  if (data->has_laser_mount && laser_frame != data->base_frame) {
    geometry_msgs::Transform transform;
    transform.translation.x = base_to_laser.translation().x();
    transform.translation.y = base_to_laser.translation().y();
    transform.translation.z = base_to_laser.translation().z();
    const Eigen::Quaterniond rotation(base_to_laser.linear());
    transform.rotation.x = rotation.x();
    transform.rotation.y = rotation.y();
    transform.rotation.z = rotation.z();
    transform.rotation.w = rotation.w();
    LaserMount mount;
    std::string mount_error;
    // A vertical scan plane cannot be used: report the mount as unknown (identity) rather than fail.
    data->has_laser_mount = laserMountFromTransform(transform, &mount, &mount_error);
    data->base_to_laser = mount.base_to_laser;
    data->laser_upside_down = mount.upside_down;
  }
  return true;
}

void setLaserMount(const BagData& data, hglasm::OdometryPipeline* pipeline) {
  if (data.has_laser_mount) pipeline->setLaserMount(data.base_to_laser, data.laser_upside_down);
}

}  // namespace hglasm_odometry
