// The live laser odometry: scans (+ wheel odometry, + an IMU) in, odometry, pose, tf, path, match statistics
// and diagnostics out. Shared by the nodelet and the node; holds no global state, so several instances can
// live in one process.
//
// A thin shell over its pieces. Threads: the subscription callbacks, ~reset and ~set_pose only append to
// the InputQueue; one worker thread per instance owns everything else that changes per scan (the
// pipeline, the sensors' mounts, log throttling, the outputs) and publishes what the diagnostics report
// under one lock; the diagnostics timer turns that into a status (diagnose()).
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/Quaternion.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "hglasm_odometry/SetPose.h"
#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/ros/conversions.h"
#include "hglasm_odometry/ros/diagnostics.h"
#include "hglasm_odometry/ros/input_queue.h"
#include "hglasm_odometry/ros/log_throttle.h"
#include "hglasm_odometry/ros/mount_cache.h"
#include "hglasm_odometry/ros/output_publisher.h"
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
  using Queue = InputQueue<sensor_msgs::LaserScanConstPtr, nav_msgs::OdometryConstPtr,
                           sensor_msgs::ImuConstPtr, PoseRequest>;

  // ---- spinner threads: they only queue (and log what they were asked)
  void subscribe();
  void scanCallback(const sensor_msgs::LaserScanConstPtr& msg);
  void odomCallback(const nav_msgs::OdometryConstPtr& msg) {
    queue_.pushOdometry(msg, msg->header.stamp.toSec());
  }
  void imuCallback(const sensor_msgs::ImuConstPtr& msg) { queue_.pushImu(msg, msg->header.stamp.toSec()); }
  bool resetCallback(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool setPoseCallback(SetPose::Request& request, SetPose::Response& response);
  void setPoseTopicCallback(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg);
  /// Validates a set-pose request and queues it for the worker; false with *message saying why not.
  bool requestPose(const geometry_msgs::PoseWithCovarianceStamped& msg, std::string* message);
  /// The diagnostics timer's status.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  // ---- the worker thread
  void workerLoop();
  /// Waits (bounded by options_.odometry_wait) until the pipeline's feeding policy lets a scan at `stamp`
  /// be processed (wheel odometry at or after it, and IMU samples to the end of its `sweep`, have arrived,
  /// or none is to be expected). False if the worker is to stop.
  bool waitForInputs(double stamp, double sweep);
  /// Hands what was queued (a reset or pose request, wheel odometry, IMU samples) to the pipeline. False
  /// if the worker is to stop.
  bool takeInputs();
  void addOdometry(const nav_msgs::Odometry& msg);
  void addImu(const sensor_msgs::Imu& msg);
  /// Sets the pipeline's laser mount for scans in `frame_id` (looked up on tf for a new frame); false
  /// while tf does not have it yet.
  bool laserMountReady(const std::string& frame_id);
  /// base_frame -> `frame` on tf, as the scans need it; false (logged, and in the diagnostics) without it.
  bool lookupLaserMount(std::string_view frame, LaserMount* mount);
  void useLaserMount(std::string_view frame, const LaserMount& mount);
  /// The rotation of the IMU's `frame` in base_frame (cached per frame); false, with a throttled warning,
  /// while tf lacks it.
  bool imuMount(std::string_view frame, geometry_msgs::Quaternion* rotation);
  void processScan(const sensor_msgs::LaserScan& msg);
  /// ~odom, ~pose, tf, ~path, ~match, ~ga_population and ~local_map of one scan.
  void publish(const std_msgs::Header& scan, const hglasm::PipelineUpdate& result, bool with_population,
               double total_ms);
  /// The log lines of one scan: a change of the scan's validity, the tracker's warning, the IMU's state.
  void reportScan(const hglasm::PipelineUpdate& result);
  /// A throttled warning for an IMU (`imu`) or wheel sample the time policy dropped, one for a sample on a
  /// new timeline.
  void reportSample(bool imu, hglasm::SampleVerdict verdict);
  /// Logs once when the IMU stops covering the steps between scans and once when it is back.
  void reportImuState(const hglasm::PipelineUpdate& update);
  /// Counts a scan into what the diagnostics report.
  void recordScan(const hglasm::TrackerUpdate& update, double cpu_ms);
  /// Sets (or clears) the tf problem the diagnostics report.
  void setTfWait(std::optional<std::string> text);
  /// Logs `text` as a warning unless the same `key` was logged less than `period` seconds ago.
  void warnThrottled(const std::string& key, const std::string& text, double period);

  const LaserOdometryOptions options_;
  const std::string name_;        // private namespace, prefixes log lines
  const std::string imu_topic_;   // resolved `imu` (log lines name it)
  const std::string odom_topic_;  // resolved `odom`
  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;

  Queue queue_;  // what the other threads hand to the worker

  // The worker's alone.
  hglasm::OdometryPipeline pipeline_;
  Queue::Inputs inputs_;                              // taken from queue_, storage reused
  hglasm::RangeScan ranges_;                          // the scan being processed, storage reused
  std::vector<hglasm::Pose2D> population_;            // the GA's, when someone watches it
  MountCache<LaserMount> laser_mount_;                // the frame of the latest scan only
  MountCache<geometry_msgs::Quaternion> imu_mounts_;  // base -> IMU frame rotation, per frame_id
  bool warned_imu_frame_ = false;
  bool warned_odom_child_frame_ = false;
  LogThrottle log_throttle_;  // per instance: rosconsole's THROTTLE macros share one timer between instances
  OutputPublisher output_;

  // What the diagnostics report: written by the worker after each scan, read by the diagnostics timer.
  std::mutex statistics_mutex_;
  WorkerStatistics statistics_;
  const DiagnosticsSettings diagnostics_settings_;
  std::uint32_t last_reported_drops_ = 0;  // the diagnostics timer's: dropped scans at its previous report

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;

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
