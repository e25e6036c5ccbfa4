// The live laser odometry: scans (+ wheel odometry, + an IMU) in, odometry, pose, tf, path, match statistics
// and diagnostics out. Shared by the nodelet and the node; holds no global state, so several instances can
// live in one process.
//
// Threads: the subscription callbacks, ~reset and ~set_pose only enqueue (scans in a bounded queue that
// drops the oldest and counts it, wheel-odometry samples, a reset or set-pose request: the later one wins)
// under one mutex and wake the worker
// through one condition variable. One worker thread per instance owns the pipeline: it takes what was
// queued, waits for odometry (hglasm::OdometryPipeline's feeding policy), converts, matches and
// publishes. Every wait of the worker is on that condition variable with stop_ in its predicate, so
// unloading never waits out a timeout.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "hglasm_odometry/SetPose.h"
#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/ros/conversions.h"
#include "hglasm_odometry/ros/parameters.h"

namespace hglasm_odometry {

class LaserOdometry {
 public:
  /// `nh` resolves the input topics (`scan`, `odom`, `imu`), `private_nh` the outputs (~odom, ~pose, ~path,
  /// ~match, ~ga_population, ~local_map), ~reset, ~set_pose and the set-pose topic (set_pose/topic, when
  /// enabled). `options` must come from loadOptions() (already validated).
  LaserOdometry(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                const LaserOdometryOptions& options);
  ~LaserOdometry();

  LaserOdometry(const LaserOdometry&) = delete;
  LaserOdometry& operator=(const LaserOdometry&) = delete;

 private:
  /// One processed scan, for the diagnostics window.
  struct ScanRecord {
    ros::WallTime time;
    double cpu_ms = 0.0;
    bool matched = false;
    bool fallback = false;
  };

  void scanCallback(const sensor_msgs::LaserScanConstPtr& msg);
  void odomCallback(const nav_msgs::OdometryConstPtr& msg);
  void imuCallback(const sensor_msgs::ImuConstPtr& msg);
  bool resetCallback(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool setPoseCallback(SetPose::Request& request, SetPose::Response& response);
  void setPoseTopicCallback(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg);
  /// Validates a set-pose request and queues it for the worker; false with *message saying why not.
  bool requestPose(const geometry_msgs::PoseWithCovarianceStamped& msg, std::string* message);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  /// A wheel-odometry sample as the callback received it.
  struct OdometrySample {
    double stamp = 0.0;
    hglasm::Pose2D pose;
    std::string child_frame;
  };

  void workerLoop();
  /// Hands the queued odometry, IMU samples and a requested reset or pose to the pipeline. Called by the
  /// worker, `lock` held.
  void takeQueuedInputs();
  /// Waits (bounded by options_.odometry_wait) until the pipeline's feeding policy lets a scan at `stamp`
  /// be processed (wheel odometry at or after it, and IMU samples to the end of its `sweep`, have arrived,
  /// or none is to be expected). False if the worker is to stop.
  bool waitForInputs(double stamp, double sweep);
  /// Looks up base -> laser for `laser_frame` (cached); false while tf does not have it yet.
  bool ensureLaserMount(const std::string& laser_frame);
  /// What the pipeline takes from an IMU message: the base's yaw rate (or yaw), rotated into base_frame.
  /// False, with a throttled warning, while tf lacks base -> the IMU's frame or for an unusable message.
  bool imuValueInBase(const sensor_msgs::Imu& msg, double* value);
  /// base -> `frame` rotation, cached per frame (a static mount); tf is asked at most every
  /// kTfRetrySeconds while it lacks it.
  bool imuMount(const std::string& frame, geometry_msgs::Quaternion* rotation);
  /// A throttled warning for an IMU (`imu`) or wheel sample the time policy dropped, one for a sample on a
  /// new timeline.
  void reportSample(bool imu, hglasm::SampleVerdict verdict);
  /// Logs once when the IMU stops covering the steps between scans and once when it is back.
  void reportImuState(const hglasm::PipelineUpdate& update);
  void processScan(const sensor_msgs::LaserScan& msg);
  /// ~odom, ~pose, tf and ~path (for a published estimate) and ~match of one scan.
  void publish(const sensor_msgs::LaserScan& msg, const hglasm::PipelineUpdate& update, double total_ms);
  void publishPose(const ros::Time& stamp, const hglasm::TrackerUpdate& update);
  /// ~local_map, only while someone subscribes: when the local map changed since it was last sent (a
  /// keyframe came, a reset) or a subscriber connected since (not latched: a new subscriber gets it with
  /// the next scan). Costs nothing but getNumSubscribers() otherwise.
  void publishLocalMap(const ros::Time& stamp);
  void publishPopulation(const ros::Time& stamp, const hglasm::TrackerUpdate& update,
                         const std::vector<hglasm::Pose2D>& population);
  /// Logs `text` as a warning unless the same `key` was logged less than `period` seconds ago.
  void warnThrottled(const std::string& key, const std::string& text, double period);

  const LaserOdometryOptions options_;
  const std::string name_;        // private namespace, prefixes log lines
  const std::string imu_topic_;   // resolved `imu` (log lines name it)
  const std::string odom_topic_;  // resolved `odom`
  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;

  // What the callbacks hand to the worker (guarded by input_mutex_; input_cv_ wakes the worker).
  std::mutex input_mutex_;
  std::condition_variable input_cv_;
  std::deque<sensor_msgs::LaserScanConstPtr> scans_;  // bounded by options_.queue_size
  std::deque<OdometrySample> odometry_;
  struct ImuSample {
    double stamp = 0.0;
    double value = 0.0;  // the base's yaw rate, or yaw with imu/use_orientation
  };
  std::deque<ImuSample> imu_;
  std::uint32_t dropped_scans_ = 0;
  bool reset_requested_ = false;
  std::optional<PoseRequest> pose_requested_;  // a reset request clears it, and it a reset request
  bool stop_ = false;

  // Worker-only state (no lock: only the worker thread touches it).
  hglasm::OdometryPipeline pipeline_;
  bool have_mount_ = false;
  std::string mount_frame_;
  std::deque<geometry_msgs::PoseStamped> path_;
  bool local_map_sent_ = false;
  std::uint64_t local_map_revision_ = 0;  // hglasm::LocalMap::revision() of the last ~local_map sent
  bool warned_odom_child_frame_ = false;

  // Diagnostics (guarded by stats_mutex_).
  std::mutex stats_mutex_;
  std::deque<ScanRecord> records_;
  std::uint64_t scans_received_ = 0;
  std::uint64_t scans_processed_ = 0;
  std::uint64_t fallbacks_ = 0;
  std::uint64_t resets_ = 0;
  hglasm::InputCounts input_counts_;  // the time policy's (pipeline_.inputCounts() after each scan)
  double time_offset_ = 0.0;          // the wheels' time offset in use, and its estimate
  double time_offset_estimate_ = 0.0;
  double degeneracy_ = 0.0;  // of the last match's scan information, and its weakest direction
  Eigen::Vector3d weakest_direction_ = Eigen::Vector3d::Zero();
  hglasm::MotionNoiseScale noise_scale_;   // the wheels' learned so far
  std::uint32_t last_reported_drops_ = 0;  // dropped_scans_ at the previous diagnostics report
  ros::WallTime last_scan_time_;
  bool waiting_for_tf_ = false;
  bool imu_stale_ = false;  // use_imu, and the last scan's rotation did not come from the IMU
  std::string tf_wait_text_;

  // Log throttling (per instance; rosconsole's THROTTLE macros share one timer between instances); guarded
  // by log_mutex_ (the odometry callback and the worker both warn).
  std::mutex log_mutex_;
  std::map<std::string, ros::WallTime> last_warning_;

  // The IMU's mounts, converted in its callback (any spinner thread).
  std::mutex imu_mount_mutex_;
  std::map<std::string, geometry_msgs::Quaternion> imu_mounts_;  // base -> IMU frame rotation, per frame_id
  ros::WallTime imu_tf_retry_;                                   // no tf lookup before this
  bool warned_imu_frame_ = false;

  // Set by ~local_map's connect callback (a spinner thread), taken by the worker: send the map again.
  std::atomic<bool> local_map_resend_{false};

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;

  ros::Publisher odom_pub_;
  ros::Publisher pose_pub_;
  ros::Publisher path_pub_;
  ros::Publisher match_pub_;
  ros::Publisher population_pub_;
  ros::Publisher local_map_pub_;
  ros::ServiceServer reset_service_;
  ros::ServiceServer set_pose_service_;
  ros::Subscriber set_pose_sub_;
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_;
  ros::Subscriber scan_sub_;
  ros::Subscriber odom_sub_;
  ros::Subscriber imu_sub_;

  std::thread worker_;  // started last, joined first
};

}  // namespace hglasm_odometry
