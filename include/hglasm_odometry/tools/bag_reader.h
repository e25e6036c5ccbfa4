// Reads laser scans, wheel odometry and the base -> laser mounting from a bag (rosbag C++ API) into core
// types: sorted by header stamp for the evaluation, and the order a subscriber receives them in (the bag's)
// for a replay. For the offline tools; needs no ROS master.
#pragma once

#include <string>
#include <vector>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm_odometry {

struct BagScan {
  double stamp = 0.0;         ///< header stamp, seconds
  double receive_time = 0.0;  ///< when the recorder received it (the bag's time), seconds
  std::size_t sequence = 0;   ///< position among the scans and odometry read, in the bag's order
  hglasm::RangeScan ranges;
  std::string frame_id;
};

struct BagOdometry {
  double stamp = 0.0;
  double receive_time = 0.0;
  std::size_t sequence = 0;
  hglasm::Pose2D pose;  ///< base in the wheel-odometry frame
};

/// One message in the order a subscriber receives it: scans[index] or odometry[index].
struct BagArrival {
  bool scan = true;
  std::size_t index = 0;
};

struct BagData {
  std::vector<BagScan> scans;         ///< sorted by stamp (bags may store a few out of order)
  std::vector<BagOdometry> odometry;  ///< sorted by stamp; empty if the topic is absent
  /// Every scan and odometry message in the bag's order (by receive time, as rosbag plays them; at one
  /// receive time, as stored).
  std::vector<BagArrival> arrivals;
  bool has_laser_mount = false;    ///< base -> laser found on /tf_static (or /tf)
  hglasm::Pose2D base_to_laser;    ///< planar part of base -> laser, after mirroring (see below)
  bool laser_upside_down = false;  ///< laser z axis points down: scans must be mirrored
  std::string base_frame;          ///< child frame of the odometry messages
};

/// Beam angles given on a tool's command line in place of the scans' own (a driver that states them wrong).
struct BeamAngleOverrides {
  bool angle_min_given = false;
  double angle_min = 0.0;  ///< radians
  bool angle_increment_given = false;
  double angle_increment = 0.0;  ///< radians
  void applyTo(hglasm::RangeScan* scan) const {
    if (angle_min_given) scan->angle_min = angle_min;
    if (angle_increment_given) scan->angle_increment = angle_increment;
  }
};

struct BagReadOptions {
  std::string scan_topic = "/scan";
  std::string odom_topic = "/odom";  ///< empty: do not read odometry
  std::string base_frame;            ///< empty: the odometry's child_frame_id, else "base_link"
  std::size_t max_scans = 0;         ///< 0 = all
};

/// False (with *error set) if the bag cannot be opened or holds no scans on the topic.
bool readBag(const std::string& path, const BagReadOptions& options, BagData* data, std::string* error);

/// Moves every odometry message `seconds` later, stamp and receive time (wheels published late by a motor
/// controller), and re-orders the arrivals by receive time.
void shiftOdometry(double seconds, BagData* data);

/// Gives `pipeline` the bag's base -> laser mount, as the live node does from tf (nothing when the bag
/// has none: the laser at the base origin).
void setLaserMount(const BagData& data, hglasm::OdometryPipeline* pipeline);

}  // namespace hglasm_odometry
