// Reads laser scans, wheel odometry and the base -> laser mounting from a bag (rosbag C++ API),
// sorted by header stamp, into core types. For the offline tools; needs no ROS master.
#pragma once

#include <string>
#include <vector>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm_odometry {

struct BagScan {
  double stamp = 0.0;  ///< header stamp, seconds
  hglasm::RangeScan ranges;
  std::string frame_id;
};

struct BagOdometry {
  double stamp = 0.0;
  hglasm::Pose2D pose;  ///< base in the wheel-odometry frame
};

struct BagData {
  std::vector<BagScan> scans;         ///< sorted by stamp (bags may store a few out of order)
  std::vector<BagOdometry> odometry;  ///< sorted by stamp; empty if the topic is absent
  bool has_laser_mount = false;       ///< base -> laser found on /tf_static (or /tf)
  hglasm::Pose2D base_to_laser;       ///< planar part of base -> laser, after mirroring (see below)
  bool laser_upside_down = false;     ///< laser z axis points down: scans must be mirrored
  std::string base_frame;             ///< child frame of the odometry messages
};

struct BagReadOptions {
  std::string scan_topic = "/scan";
  std::string odom_topic = "/odom";  ///< empty: do not read odometry
  std::string base_frame;            ///< empty: the odometry's child_frame_id, else "base_link"
  std::size_t max_scans = 0;         ///< 0 = all
};

/// False (with *error set) if the bag cannot be opened or holds no scans on the topic.
bool readBag(const std::string& path, const BagReadOptions& options, BagData* data, std::string* error);

/// Gives `pipeline` the bag's base -> laser mount, as the live node does from tf (nothing when the bag
/// has none: the laser at the base origin).
void setLaserMount(const BagData& data, hglasm::OdometryPipeline* pipeline);

}  // namespace hglasm_odometry
