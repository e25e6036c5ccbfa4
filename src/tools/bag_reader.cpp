// Reads scans, wheel odometry and the base -> laser mounting from a bag with the rosbag C++ API; the
// mounting is looked up with tf2::BufferCore, the very code the live node's tf2_ros::Buffer runs.
#include "hglasm_odometry/tools/bag_reader.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include "hglasm_odometry/ros/conversions.h"

namespace hglasm_odometry {

namespace {

// tf2::BufferCore refuses a rotation whose squared norm is further than this from 1.
constexpr double kTf2QuaternionTolerance = 10e-3;

std::string withSlash(const std::string& topic) {
  return !topic.empty() && topic.front() != '/' ? "/" + topic : topic;
}

bool isFinite(const geometry_msgs::Transform& transform) {
  const auto& t = transform.translation;
  const auto& q = transform.rotation;
  return std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z) && std::isfinite(q.x) &&
         std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
}

/// A rotation tf2 accepts, unchanged (so the lookup is the live node's to the bit); one it refuses is
/// normalised, and an unset (zero) quaternion becomes the identity, as hand-written bags need.
void makeAcceptableToTf2(geometry_msgs::Quaternion* q) {
  const double norm2 = q->x * q->x + q->y * q->y + q->z * q->z + q->w * q->w;
  if (std::abs(norm2 - 1.0) < kTf2QuaternionTolerance) return;
  if (norm2 < 1e-18) {
    q->x = q->y = q->z = 0.0;
    q->w = 1.0;
    return;
  }
  const double norm = std::sqrt(norm2);
  q->x /= norm;
  q->y /= norm;
  q->z /= norm;
  q->w /= norm;
}

/// Transforms by child frame (slashes stripped): the candidates for the laser mounting.
using FrameTransforms = std::map<std::string, geometry_msgs::TransformStamped>;

void collectTransforms(const tf2_msgs::TFMessage& message, bool overwrite, FrameTransforms* frames) {
  for (geometry_msgs::TransformStamped stamped : message.transforms) {
    stamped.child_frame_id = stripLeadingSlash(stamped.child_frame_id);
    stamped.header.frame_id = stripLeadingSlash(stamped.header.frame_id);
    if (stamped.child_frame_id.empty() || stamped.header.frame_id.empty() ||
        stamped.child_frame_id == stamped.header.frame_id || !isFinite(stamped.transform)) {
      continue;
    }
    if (!overwrite && frames->count(stamped.child_frame_id)) continue;
    (*frames)[stamped.child_frame_id] = stamped;
  }
}

/// base -> laser from tf2::BufferCore. Every transform goes in as static: only mountings matter, and a
/// static lookup is neither interpolated nor limited to a time window. /tf_static wins over /tf.
bool lookupMount(const FrameTransforms& static_frames, const FrameTransforms& dynamic_frames,
                 const std::string& base, const std::string& laser, geometry_msgs::Transform* base_to_laser) {
  tf2::BufferCore buffer;
  const auto add = [&buffer](geometry_msgs::TransformStamped stamped) {
    makeAcceptableToTf2(&stamped.transform.rotation);
    buffer.setTransform(stamped, "bag", true);
  };
  for (const auto& entry : dynamic_frames) {
    if (!static_frames.count(entry.first)) add(entry.second);
  }
  for (const auto& entry : static_frames) add(entry.second);
  try {
    *base_to_laser = buffer.lookupTransform(base, laser, ros::Time(0)).transform;
    return true;
  } catch (const tf2::TransformException&) {
    return false;
  }
}

/// What one pass over the bag's messages collects.
struct BagContents {
  FrameTransforms static_frames;   ///< latest of each child frame on /tf_static
  FrameTransforms dynamic_frames;  ///< first of each child frame on /tf
  std::string odom_child_frame;
  std::string laser_frame;
};

/// Reads the scans, odometry and transforms; with max_scans, stops a little after the last wanted
/// scan so that its odometry is bracketed. Throws rosbag::BagException.
void readMessages(rosbag::Bag* bag, const BagReadOptions& options, BagData* data, BagContents* contents) {
  const std::string scan_topic = withSlash(options.scan_topic);
  const std::string odom_topic = withSlash(options.odom_topic);
  std::vector<std::string> topics = {scan_topic, "/tf_static", "/tf"};
  if (!odom_topic.empty()) topics.push_back(odom_topic);

  bool scans_complete = false;
  double last_wanted_stamp = 0.0;
  rosbag::View view(*bag, rosbag::TopicQuery(topics));
  for (const rosbag::MessageInstance& message : view) {
    if (scans_complete && message.getTime().toSec() > last_wanted_stamp + 1.0) break;
    const std::string& topic = message.getTopic();
    if (topic == scan_topic) {
      if (scans_complete) continue;
      const auto scan = message.instantiate<sensor_msgs::LaserScan>();
      if (!scan) continue;
      BagScan bag_scan;
      bag_scan.stamp = scan->header.stamp.toSec();
      bag_scan.receive_time = message.getTime().toSec();
      bag_scan.sequence = data->scans.size() + data->odometry.size();
      bag_scan.frame_id = stripLeadingSlash(scan->header.frame_id);
      bag_scan.ranges = rangeScanFromMsg(*scan);
      if (contents->laser_frame.empty()) contents->laser_frame = bag_scan.frame_id;
      data->scans.push_back(std::move(bag_scan));
      if (options.max_scans > 0 && data->scans.size() >= options.max_scans) {
        scans_complete = true;
        last_wanted_stamp = std::max(message.getTime().toSec(), data->scans.back().stamp);
      }
    } else if (topic == odom_topic) {
      const auto odom = message.instantiate<nav_msgs::Odometry>();
      BagOdometry sample;
      if (!odom || !pose2DFromOdometryMsg(*odom, &sample.pose)) continue;
      sample.stamp = odom->header.stamp.toSec();
      sample.receive_time = message.getTime().toSec();
      sample.sequence = data->scans.size() + data->odometry.size();
      if (contents->odom_child_frame.empty())
        contents->odom_child_frame = stripLeadingSlash(odom->child_frame_id);
      data->odometry.push_back(sample);
    } else if (topic == "/tf_static" || topic == "/tf") {
      const auto tf = message.instantiate<tf2_msgs::TFMessage>();
      if (!tf) continue;
      // Latest static transform wins; from /tf keep the first of each frame (only mountings matter).
      const bool is_static = topic == "/tf_static";
      collectTransforms(*tf, is_static, is_static ? &contents->static_frames : &contents->dynamic_frames);
    }
  }
}

/// Fills the mounting fields of `data` from the collected transforms.
void resolveMount(const BagContents& contents, BagData* data) {
  if (contents.laser_frame == data->base_frame) {
    data->has_laser_mount = true;  // the laser is the base: the identity
    return;
  }
  geometry_msgs::Transform transform;
  data->has_laser_mount = lookupMount(contents.static_frames, contents.dynamic_frames, data->base_frame,
                                      contents.laser_frame, &transform);
  if (!data->has_laser_mount) return;
  LaserMount mount;
  std::string mount_error;
  // A vertical scan plane cannot be used: report the mount as unknown (identity) rather than fail.
  data->has_laser_mount = laserMountFromTransform(transform, &mount, &mount_error);
  data->base_to_laser = mount.base_to_laser;
  data->laser_upside_down = mount.upside_down;
}

/// data->arrivals: every message by receive time; at one receive time, in the order read.
void orderArrivals(BagData* data) {
  data->arrivals.clear();
  for (std::size_t i = 0; i < data->scans.size(); ++i) data->arrivals.push_back(BagArrival{true, i});
  for (std::size_t i = 0; i < data->odometry.size(); ++i) data->arrivals.push_back(BagArrival{false, i});
  const auto key = [data](const BagArrival& arrival) {
    return arrival.scan
               ? std::make_pair(data->scans[arrival.index].receive_time, data->scans[arrival.index].sequence)
               : std::make_pair(data->odometry[arrival.index].receive_time,
                                data->odometry[arrival.index].sequence);
  };
  std::sort(data->arrivals.begin(), data->arrivals.end(),
            [&](const BagArrival& a, const BagArrival& b) { return key(a) < key(b); });
}

}  // namespace

void shiftOdometry(double seconds, BagData* data) {
  for (BagOdometry& sample : data->odometry) {
    sample.stamp += seconds;
    sample.receive_time += seconds;
  }
  orderArrivals(data);
}

bool readBag(const std::string& path, const BagReadOptions& options, BagData* data, std::string* error) {
  *data = BagData();
  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& exception) {
    if (error) *error = "cannot open bag '" + path + "': " + exception.what();
    return false;
  }
  BagContents contents;
  try {
    readMessages(&bag, options, data, &contents);
  } catch (const rosbag::BagException& exception) {
    if (error) *error = "error reading bag '" + path + "': " + exception.what();
    return false;
  }
  bag.close();

  if (data->scans.empty()) {
    if (error) {
      *error = "bag '" + path + "' holds no sensor_msgs/LaserScan on topic '" +
               withSlash(options.scan_topic) + "'";
    }
    return false;
  }
  const auto by_stamp = [](const auto& a, const auto& b) { return a.stamp < b.stamp; };
  std::stable_sort(data->scans.begin(), data->scans.end(), by_stamp);
  std::stable_sort(data->odometry.begin(), data->odometry.end(), by_stamp);
  orderArrivals(data);

  data->base_frame = stripLeadingSlash(options.base_frame);
  if (data->base_frame.empty()) data->base_frame = contents.odom_child_frame;
  if (data->base_frame.empty()) data->base_frame = "base_link";
  resolveMount(contents, data);
  return true;
}

void setLaserMount(const BagData& data, hglasm::OdometryPipeline* pipeline) {
  if (data.has_laser_mount) pipeline->setLaserMount(data.base_to_laser, data.laser_upside_down);
}

}  // namespace hglasm_odometry
