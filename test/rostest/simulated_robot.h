// Shared by the rostest nodes that drive laser-odometry nodelets with a simulated robot: the publishing
// adapter of the tests' one simulated robot (test/core/simulated_robot.h: scans of a polygonal room, wheel
// odometry, the laser mount, the gyro) and a recorder of what the nodelets publish (~odom, ~pose, ~match,
// /rosout, /diagnostics, /tf).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "../core/simulated_robot.h"
#include "../core/test_expect.h"
#include "../core/test_util.h"
#include "hglasm_odometry/Match.h"
#include "hglasm_odometry/ros/conversions.h"

namespace hglasm_odometry {
namespace rostest_sim {

using hglasm::Pose2D;
using hglasm_test::deg;
using hglasm_test::LaserSpec;
using hglasm_test::Path;

constexpr double kStampOrigin = 1000.0;  // scan stamps are kStampOrigin + simulated time (no sim time)

inline bool finite(const boost::array<double, 36>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}
inline bool finite(const geometry_msgs::Pose& p) {
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z) &&
         std::isfinite(p.orientation.x) && std::isfinite(p.orientation.y) && std::isfinite(p.orientation.z) &&
         std::isfinite(p.orientation.w);
}
inline bool finite(const geometry_msgs::Pose2D& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
}

inline Pose2D pose2D(const geometry_msgs::Pose& pose) {
  Pose2D out;
  pose2DFromPoseMsg(pose, &out);
  return out;
}

inline std::string describe(const Match& m) {
  std::ostringstream text;
  text << "match @" << m.header.stamp << ": status " << m.status_text << " matched " << int(m.matched)
       << " fallback " << int(m.fallback) << " keyframe " << int(m.new_keyframe) << " reset " << int(m.reset)
       << " prediction " << int(m.prediction_source) << " fitness " << m.fitness_ratio << " valid "
       << m.valid_points << " invalid " << m.invalid_points << " dropped " << m.dropped_scans
       << " odometry time offset " << m.odometry_time_offset << " (estimate "
       << m.odometry_time_offset_estimate << ")";
  return text.str();
}

// ------------------------------------------------------------------ what the nodelets publish

/// Everything on /rosout, /diagnostics and /tf (filtered per instance when read).
struct Recorder {
  std::mutex mutex;
  std::vector<rosgraph_msgs::Log> logs;
  std::vector<diagnostic_msgs::DiagnosticStatus> diagnostics_all;
  std::vector<geometry_msgs::TransformStamped> transforms;

  void onLog(const rosgraph_msgs::LogConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex);
    logs.push_back(*msg);
  }
  void onDiagnostics(const diagnostic_msgs::DiagnosticArrayConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& status : msg->status) diagnostics_all.push_back(status);
  }
  void onTf(const tf2_msgs::TFMessageConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& t : msg->transforms) transforms.push_back(t);
  }

  /// Log lines of `instance` ("/odo_a"; "" = any) at `level` (rosgraph_msgs::Log::WARN, ...), from index
  /// `from` on.
  std::vector<std::string> lines(const std::string& instance, std::uint8_t level, std::size_t from = 0) {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::string> out;
    for (std::size_t i = from; i < logs.size(); ++i) {
      if (logs[i].level == level &&
          (instance.empty() || logs[i].msg.find("[" + instance + "]") != std::string::npos)) {
        out.push_back(logs[i].msg);
      }
    }
    return out;
  }
  std::size_t logCount() {
    std::lock_guard<std::mutex> lock(mutex);
    return logs.size();
  }
  /// Statuses of `instance` (diagnostic name "odo_a: laser odometry"), from index `from` on.
  std::vector<diagnostic_msgs::DiagnosticStatus> statuses(const std::string& instance, std::size_t from = 0) {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<diagnostic_msgs::DiagnosticStatus> out;
    const std::string prefix = instance.substr(1) + ":";
    for (std::size_t i = from; i < diagnostics_all.size(); ++i) {
      if (diagnostics_all[i].name.rfind(prefix, 0) == 0) out.push_back(diagnostics_all[i]);
    }
    return out;
  }
  std::size_t diagnosticsCount() {
    std::lock_guard<std::mutex> lock(mutex);
    return diagnostics_all.size();
  }
};

inline std::string value(const diagnostic_msgs::DiagnosticStatus& status, const std::string& key) {
  for (const auto& kv : status.values) {
    if (kv.key == key) return kv.value;
  }
  return "";
}

/// Log lines, one per line, for a failure message.
inline std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += "\n  " + l;
  return out;
}

/// Waits (wall clock, spinning in the background) until `done` or `timeout` seconds.
inline bool waitFor(const std::function<bool()>& done, double timeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    if (done()) return true;
    ros::WallDuration(0.005).sleep();
  }
  return done();
}

// ------------------------------------------------------------------ one simulated robot + its odometry

/// The LaserScan message of simulated ranges.
inline sensor_msgs::LaserScan scanMsg(const hglasm::RangeScan& ranges, const ros::Time& stamp,
                                      const std::string& frame) {
  sensor_msgs::LaserScan msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.angle_min = static_cast<float>(ranges.angle_min);
  msg.angle_increment = static_cast<float>(ranges.angle_increment);
  msg.angle_max = static_cast<float>(ranges.angle_min + (ranges.ranges.size() - 1) * ranges.angle_increment);
  msg.range_min = static_cast<float>(ranges.range_min);
  msg.range_max = static_cast<float>(ranges.range_max);
  msg.scan_time = 0.1f;
  msg.ranges = ranges.ranges;
  return msg;
}

/// A LaserScan message of a laser at `laser_pose` in `world`.
inline sensor_msgs::LaserScan scanMsg(const hglasm_test::World& world, const Pose2D& laser_pose,
                                      const LaserSpec& laser, const ros::Time& stamp,
                                      const std::string& frame) {
  return scanMsg(hglasm_test::simulateRanges(world, laser_pose, laser), stamp, frame);
}

struct RobotSetup {
  std::string instance;     // private namespace of the nodelet, e.g. "/odo_a"
  std::string scan_topic;   // what the nodelet subscribes as `scan`
  std::string wheel_topic;  // what it subscribes as `odom` ("" = no wheel odometry published)
  std::string odom_frame, base_frame, laser_frame;
  Pose2D mount;  // base -> laser
  Path path;     // base pose in the world over simulated time
  LaserSpec laser;
};

class Robot {
 public:
  Robot(ros::NodeHandle& nh, RobotSetup setup)
      : setup_(std::move(setup)), sim_(setup_.path, hglasm_test::room(), setup_.laser, -1e9) {
    sim_.setMount(setup_.mount);
    sim_.setWheelJump(-std::numeric_limits<double>::infinity(), Pose2D());  // setWheelOffset's, at any time
    if (!setup_.wheel_topic.empty()) sim_.enableWheels();
    scan_pub_ = nh.advertise<sensor_msgs::LaserScan>(setup_.scan_topic, 100);
    if (!setup_.wheel_topic.empty()) wheel_pub_ = nh.advertise<nav_msgs::Odometry>(setup_.wheel_topic, 1000);
    odom_sub_ = nh.subscribe<nav_msgs::Odometry>(setup_.instance + "/odom", 10000,
                                                 [this](const nav_msgs::OdometryConstPtr& m) {
                                                   std::lock_guard<std::mutex> lock(mutex_);
                                                   odom_.push_back(*m);
                                                 });
    pose_sub_ = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        setup_.instance + "/pose", 10000, [this](const geometry_msgs::PoseWithCovarianceStampedConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          pose_.push_back(*m);
        });
    match_sub_ = nh.subscribe<Match>(setup_.instance + "/match", 10000, [this](const MatchConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      match_.push_back(*m);
    });
  }

  const RobotSetup& setup() const { return setup_; }
  void setLaser(const LaserSpec& laser) {
    setup_.laser = laser;
    sim_.setLaser(laser);
  }
  /// The simulation behind the messages (its gyro feeds the IMU rostest's publisher).
  hglasm_test::SimulatedRobot& sim() { return sim_; }

  /// Subscribers of the nodelet connected to our publishers, and our subscribers to its outputs.
  bool connected() const {
    return scan_pub_.getNumSubscribers() > 0 && (!wheel_pub_ || wheel_pub_.getNumSubscribers() > 0) &&
           odom_sub_.getNumPublishers() > 0 && match_sub_.getNumPublishers() > 0 &&
           pose_sub_.getNumPublishers() > 0;
  }

  Pose2D truth(double t) const { return sim_.truth(t); }

  /// The scan the laser takes at simulated time t (stamped `stamp`).
  sensor_msgs::LaserScan scanAt(double t, const ros::Time& stamp) const {
    return scanMsg(sim_.rangesAt(t), stamp, setup_.laser_frame);
  }

  /// Wheel odometry (exact, plus `wheel_offset` applied in the odometry frame; counting `wheel_turn_scale`
  /// of every turn if set) at 50 Hz stamps up to `until`, continuing from the last published stamp
  /// (restarting if the stamps went back).
  void publishWheel(double t_until, const ros::Time& stamp_until) {
    if (!wheel_pub_) return;
    // The timeline is mapped onto ros::Time here; the simulation's own stamp offset stays 0.
    const double stamp_offset = stamp_until.toSec() - t_until;
    // Restart when the stamps went back or onto another timeline (ros::Time rounds to nanoseconds: offsets
    // that differ by less are the same timeline).
    hglasm_test::SimulatedWheels& wheels = sim_.wheels();
    if (wheels.time() > t_until + 1e-9 || std::abs(stamp_offset - wheel_stamp_offset_) > 1e-6) {
      wheels.restart(t_until - 0.1);
    }
    wheel_stamp_offset_ = stamp_offset;
    hglasm_test::RobotSink sink;
    sink.wheels = [&](double time, const Pose2D& pose) {
      nav_msgs::Odometry msg;
      msg.header.stamp = ros::Time(time + stamp_offset);
      msg.header.frame_id = "wheel_odom";
      msg.child_frame_id = setup_.base_frame;
      msg.pose.pose = poseMsgFromPose2D(pose);
      wheel_pub_.publish(msg);
    };
    sim_.advanceWheels(t_until, sink);
  }
  /// Wheel odometry offset by `offset` in the odometry frame, from the next sample on.
  void setWheelOffset(const Pose2D& offset) {
    sim_.setWheelJump(-std::numeric_limits<double>::infinity(), offset);
  }
  /// Wheels that count `scale` of every turn (a skid-steer robot's slip), from the next sample on.
  void setWheelTurnScale(double scale) {
    // Slipping wheels integrate their own increments; exact ones are the truth itself (no rounding).
    hglasm_test::SimulatedWheels& wheels = sim_.wheels();
    wheels.restart(wheels.time());
    if (scale == 1.0) {
      wheels.setExact();
    } else {
      wheels.setErrors(0.0, 0.0, scale);
    }
  }

  void publishScan(const sensor_msgs::LaserScan& scan) { scan_pub_.publish(scan); }

  std::size_t matchCount() {
    std::lock_guard<std::mutex> lock(mutex_);
    return match_.size();
  }
  std::size_t odomCount() {
    std::lock_guard<std::mutex> lock(mutex_);
    return odom_.size();
  }
  /// Waits for the match number `index` (0-based) and the ~odom published with it (~odom and ~match
  /// travel on separate connections).
  bool waitForMatch(std::size_t index, double timeout = 5.0) {
    return waitFor(
        [this, index] {
          std::lock_guard<std::mutex> lock(mutex_);
          if (match_.size() <= index) return false;
          if (match_[index].status == Match::STATUS_STALE) return true;  // dropped: no pose comes with it
          const ros::Time stamp = match_[index].header.stamp;
          return std::any_of(odom_.begin(), odom_.end(),
                             [&stamp](const nav_msgs::Odometry& o) { return o.header.stamp == stamp; });
        },
        timeout);
  }
  Match match(std::size_t index) {
    std::lock_guard<std::mutex> lock(mutex_);
    return match_.at(index);
  }
  /// The newest ~odom stamped `stamp`.
  bool odomAt(const ros::Time& stamp, nav_msgs::Odometry* out) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = odom_.rbegin(); it != odom_.rend(); ++it) {
      if (it->header.stamp == stamp) {
        *out = *it;
        return true;
      }
    }
    return false;
  }
  std::vector<nav_msgs::Odometry> odometry() {
    std::lock_guard<std::mutex> lock(mutex_);
    return odom_;
  }
  std::vector<geometry_msgs::PoseWithCovarianceStamped> poses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return pose_;
  }
  std::vector<Match> matches() {
    std::lock_guard<std::mutex> lock(mutex_);
    return match_;
  }

 private:
  RobotSetup setup_;
  hglasm_test::SimulatedRobot sim_;
  ros::Publisher scan_pub_, wheel_pub_;
  ros::Subscriber odom_sub_, pose_sub_, match_sub_;
  std::mutex mutex_;
  std::vector<nav_msgs::Odometry> odom_;
  std::vector<geometry_msgs::PoseWithCovarianceStamped> pose_;
  std::vector<Match> match_;
  double wheel_stamp_offset_ = 0.0;
};

/// Clockwise circle of radius 1.5 m through the origin at 0.5 m/s (clear of the room's obstacles).
inline Pose2D circlePath(double t) {
  const double radius = 1.5, rate = 0.5 / radius;
  return hglasm_test::rawPose(radius * std::sin(rate * t), -radius + radius * std::cos(rate * t),
                              hglasm_test::angleDiff(-rate * t, 0.0));
}

/// Counter-clockwise circle of radius 1 m around (0, 1) at 0.4 m/s.
inline Pose2D otherCirclePath(double t) {
  const double radius = 1.0, rate = 0.4 / radius;
  return hglasm_test::rawPose(radius * std::sin(rate * t), 1.0 - radius * std::cos(rate * t),
                              hglasm_test::angleDiff(rate * t, 0.0));
}

inline void sendStaticTf(tf2_ros::StaticTransformBroadcaster* broadcaster, const RobotSetup& setup) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(kStampOrigin);
  t.header.frame_id = setup.base_frame;
  t.child_frame_id = setup.laser_frame;
  t.transform = transformMsgFromPose2D(setup.mount);
  broadcaster->sendTransform(t);
}

/// One scan of `robot` at simulated time t (stamped kStampOrigin + t), its wheel odometry first; the match
/// and the ~odom published with it.
inline bool scanStep(Robot& robot, double t, Match* match, nav_msgs::Odometry* odom) {
  const ros::Time stamp(kStampOrigin + t);
  const std::size_t index = robot.matchCount();
  robot.publishWheel(t + 0.02, stamp + ros::Duration(0.02));
  robot.publishScan(robot.scanAt(t, stamp));
  if (!robot.waitForMatch(index)) return false;
  *match = robot.match(index);
  return robot.odomAt(stamp, odom);
}

}  // namespace rostest_sim
}  // namespace hglasm_odometry
