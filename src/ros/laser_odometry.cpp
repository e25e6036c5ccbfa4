#include "hglasm_odometry/ros/laser_odometry.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <sstream>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Path.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "hglasm_odometry/Match.h"

namespace hglasm_odometry {
namespace {

/// CPU time of the calling thread, milliseconds.
double threadCpuMs() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return now.tv_sec * 1e3 + now.tv_nsec * 1e-6;
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// Subscriber queues only need to absorb bursts until the callback moves the message into the bounded
/// queue (callbacks are cheap); they are not where scans are dropped.
constexpr int kScanSubscriberQueue = 50;
constexpr int kOdomSubscriberQueue = 200;
constexpr double kTfRetrySeconds = 0.05;  // wall time between tf lookups while waiting for base -> laser
constexpr std::size_t kMaxQueuedOdometry = 10000;  // samples kept while the worker waits (100 s at 100 Hz)
constexpr int kImuSubscriberQueue = 1000;
constexpr std::size_t kMaxQueuedImu = 20000;  // 20 s at 1 kHz
constexpr double kStaleWarnPeriod = 10.0;     // seconds between warnings about inputs stamped out of order

}  // namespace

LaserOdometry::LaserOdometry(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                             const LaserOdometryOptions& options)
    : options_(options),
      name_(private_nh.getNamespace()),
      imu_topic_(nh.resolveName("imu")),
      odom_topic_(nh.resolveName("odom")),
      nh_(nh),
      private_nh_(private_nh),
      pipeline_(options.tracker, options.odometry_wait > 0.0),
      tf_listener_(tf_buffer_),
      diagnostics_(nh, private_nh, private_nh.getNamespace()) {
  // Outputs first, inputs last: nothing arrives before there is somewhere to publish it.
  odom_pub_ = private_nh_.advertise<nav_msgs::Odometry>("odom", 50);
  pose_pub_ = private_nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 50);
  if (options_.path_length > 0) path_pub_ = private_nh_.advertise<nav_msgs::Path>("path", 2);
  match_pub_ = private_nh_.advertise<Match>("match", 50);
  if (options_.publish_population) {
    population_pub_ = private_nh_.advertise<visualization_msgs::MarkerArray>("ga_population", 2);
  }
  local_map_pub_ = private_nh_.advertise<sensor_msgs::PointCloud2>(
      "local_map", 2, [this](const ros::SingleSubscriberPublisher&) { local_map_resend_ = true; });
  reset_service_ = private_nh_.advertiseService("reset", &LaserOdometry::resetCallback, this);
  set_pose_service_ = private_nh_.advertiseService("set_pose", &LaserOdometry::setPoseCallback, this);

  diagnostics_.setHardwareID("none");
  diagnostics_.add("laser odometry", this, &LaserOdometry::diagnose);
  diagnostics_timer_ =
      private_nh_.createWallTimer(ros::WallDuration(options_.diagnostics.period),
                                  [this](const ros::WallTimerEvent&) { diagnostics_.force_update(); });

  worker_ = std::thread(&LaserOdometry::workerLoop, this);

  scan_sub_ = nh_.subscribe("scan", kScanSubscriberQueue, &LaserOdometry::scanCallback, this,
                            ros::TransportHints().tcpNoDelay());
  if (options_.tracker.prediction.use_odometry) {
    odom_sub_ = nh_.subscribe("odom", kOdomSubscriberQueue, &LaserOdometry::odomCallback, this,
                              ros::TransportHints().tcpNoDelay());
  }
  if (options_.tracker.prediction.use_imu) {
    imu_sub_ = nh_.subscribe("imu", kImuSubscriberQueue, &LaserOdometry::imuCallback, this,
                             ros::TransportHints().tcpNoDelay());
  }
  if (options_.set_pose.topic_enabled) {
    set_pose_sub_ =
        private_nh_.subscribe(options_.set_pose.topic, 5, &LaserOdometry::setPoseTopicCallback, this);
    ROS_INFO_STREAM("[" << name_ << "] taking poses to continue from on " << set_pose_sub_.getTopic());
  }
  ROS_INFO_STREAM("[" << name_ << "] laser odometry on " << scan_sub_.getTopic()
                      << (options_.tracker.prediction.use_odometry ? " + " + odom_sub_.getTopic()
                                                                   : std::string(" (no wheel odometry)"))
                      << (options_.tracker.prediction.use_imu ? " + " + imu_topic_ : std::string()) << ": "
                      << summarize(options_));
}

LaserOdometry::~LaserOdometry() {
  scan_sub_.shutdown();
  odom_sub_.shutdown();
  imu_sub_.shutdown();
  set_pose_sub_.shutdown();
  reset_service_.shutdown();
  set_pose_service_.shutdown();
  diagnostics_timer_.stop();
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    stop_ = true;
  }
  input_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void LaserOdometry::scanCallback(const sensor_msgs::LaserScanConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    if (scans_.size() >= static_cast<std::size_t>(options_.queue_size)) {
      scans_.pop_front();  // the oldest scan is the least useful one to a live estimate
      ++dropped_scans_;
    }
    scans_.push_back(msg);
  }
  input_cv_.notify_all();
  std::lock_guard<std::mutex> lock(stats_mutex_);
  ++scans_received_;
  last_scan_time_ = ros::WallTime::now();
}

void LaserOdometry::odomCallback(const nav_msgs::OdometryConstPtr& msg) {
  OdometrySample sample;
  if (!pose2DFromOdometryMsg(*msg, &sample.pose)) {
    warnThrottled("odom_nan", "wheel odometry message with a non-finite pose ignored", 10.0);
    return;
  }
  sample.stamp = msg->header.stamp.toSec();
  sample.child_frame = stripLeadingSlash(msg->child_frame_id);
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    // The worker takes the samples before every scan; this bound only matters while it waits for tf.
    if (odometry_.size() >= kMaxQueuedOdometry) odometry_.pop_front();
    odometry_.push_back(std::move(sample));
  }
  input_cv_.notify_all();
}

void LaserOdometry::imuCallback(const sensor_msgs::ImuConstPtr& msg) {
  // Converted here, outside the worker's lock: a tf lookup per message must not hold up the other inputs.
  ImuSample sample;
  if (!imuValueInBase(*msg, &sample.value)) return;
  sample.stamp = msg->header.stamp.toSec();
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    if (imu_.size() >= kMaxQueuedImu) imu_.pop_front();
    imu_.push_back(sample);
  }
  input_cv_.notify_all();
}

bool LaserOdometry::imuValueInBase(const sensor_msgs::Imu& msg, double* value) {
  geometry_msgs::Quaternion mount;
  if (!imuMount(stripLeadingSlash(msg.header.frame_id), &mount)) return false;
  std::string error;
  if (!imuValueFromMsg(msg, mount, options_.tracker.prediction.imu.use_orientation, value, &error)) {
    warnThrottled("imu_bad", "IMU sample on " + imu_topic_ + " ignored: " + error, 10.0);
    return false;
  }
  return true;
}

bool LaserOdometry::imuMount(const std::string& frame, geometry_msgs::Quaternion* rotation) {
  std::lock_guard<std::mutex> lock(imu_mount_mutex_);
  const auto known = imu_mounts_.find(frame);
  if (known != imu_mounts_.end()) {
    *rotation = known->second;
    return true;
  }
  geometry_msgs::Quaternion found;
  found.w = 1.0;
  if (frame.empty() && !warned_imu_frame_) {
    warned_imu_frame_ = true;
    ROS_WARN_STREAM("[" << name_ << "] IMU messages on " << imu_topic_
                        << " carry no frame_id; assuming the IMU is aligned with " << options_.base_frame);
  } else if (!frame.empty() && frame != options_.base_frame) {
    const ros::WallTime now = ros::WallTime::now();
    if (now < imu_tf_retry_) return false;
    try {
      found = tf_buffer_.lookupTransform(options_.base_frame, frame, ros::Time(0)).transform.rotation;
    } catch (const tf2::TransformException& ex) {
      imu_tf_retry_ = now + ros::WallDuration(kTfRetrySeconds);
      warnThrottled("imu_tf",
                    "IMU samples dropped: no transform " + options_.base_frame + " -> " + frame +
                        " (base_frame -> the IMU's frame_id) on tf yet (" + ex.what() + ")",
                    options_.tf_warn_period);
      return false;
    }
  }
  imu_mounts_.emplace(frame, found);
  *rotation = found;
  return true;
}

bool LaserOdometry::resetCallback(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    reset_requested_ = true;
    pose_requested_.reset();
  }
  input_cv_.notify_all();
  ROS_INFO_STREAM("[" << name_ << "] reset requested: restarting from the origin at the next scan");
  return true;
}

bool LaserOdometry::requestPose(const geometry_msgs::PoseWithCovarianceStamped& msg, std::string* message) {
  PoseRequest request;
  std::string error;
  if (!poseRequestFromMsg(msg, options_.odom_frame, &request, &error)) {
    *message = "pose refused: " + error;
    return false;
  }
  if (request.stamp == 0.0) request.stamp = ros::Time::now().toSec();
  std::ostringstream text;
  text << "continuing from x " << request.pose.x << " m, y " << request.pose.y << " m, yaw "
       << request.pose.theta << " rad in " << options_.odom_frame << " at the next scan";
  if (request.covariance_replaced) {
    text << " (its covariance is not a valid x, y, yaw covariance: zero used, the pose taken as exact)";
  }
  *message = text.str();
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    pose_requested_ = request;
    reset_requested_ = false;
  }
  input_cv_.notify_all();
  return true;
}

bool LaserOdometry::setPoseCallback(SetPose::Request& request, SetPose::Response& response) {
  response.success = requestPose(request.pose, &response.message);
  if (response.success) {
    ROS_INFO_STREAM("[" << name_ << "] ~set_pose: " << response.message);
  } else {
    ROS_WARN_STREAM("[" << name_ << "] ~set_pose: " << response.message);
  }
  return true;  // a refused pose is an answer, not a failed call
}

void LaserOdometry::setPoseTopicCallback(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
  std::string message;
  if (requestPose(*msg, &message)) {
    ROS_INFO_STREAM("[" << name_ << "] " << set_pose_sub_.getTopic() << ": " << message);
  } else {
    ROS_WARN_STREAM("[" << name_ << "] " << set_pose_sub_.getTopic() << ": " << message);
  }
}

void LaserOdometry::takeQueuedInputs() {
  if (reset_requested_) {
    pipeline_.reset();
    reset_requested_ = false;
  }
  if (pose_requested_) {
    if (!pipeline_.setPose(pose_requested_->stamp, pose_requested_->pose, pose_requested_->covariance)) {
      ROS_WARN_STREAM("[" << name_ << "] the pose to continue from was refused by the tracker");
    }
    pose_requested_.reset();
  }
  for (const OdometrySample& sample : odometry_) {
    if (!sample.child_frame.empty() && sample.child_frame != options_.base_frame &&
        !warned_odom_child_frame_) {
      warned_odom_child_frame_ = true;  // once: the configuration will not change by itself
      ROS_WARN_STREAM("[" << name_ << "] wheel odometry on " << odom_topic_ << " is of frame \""
                          << sample.child_frame << "\", not of base_frame \"" << options_.base_frame
                          << "\"; it is used as the motion of base_frame anyway");
    }
    reportSample(false, pipeline_.addOdometry(sample.stamp, sample.pose));
  }
  odometry_.clear();
  for (const ImuSample& sample : imu_) reportSample(true, pipeline_.addImu(sample.stamp, sample.value));
  imu_.clear();
}

void LaserOdometry::reportSample(bool imu, hglasm::SampleVerdict verdict) {
  if (verdict == hglasm::SampleVerdict::kTaken || verdict == hglasm::SampleVerdict::kInvalid) return;
  const std::string input = imu ? "IMU data on " + imu_topic_ : "wheel odometry on " + odom_topic_;
  if (verdict == hglasm::SampleVerdict::kStale) {
    warnThrottled(
        "stale " + input,
        input + " stamped before its newest sample: dropped (the time policy; counted in diagnostics)",
        kStaleWarnPeriod);
  } else if (verdict == hglasm::SampleVerdict::kNewTimeline) {
    ROS_WARN_STREAM("[" << name_ << "] " << input
                        << " went back in time by more than time/reset_on_jump_back "
                        << options_.tracker.reset_on_jump_back << " s: its earlier samples are forgotten");
  }
}

void LaserOdometry::reportImuState(const hglasm::PipelineUpdate& update) {
  if (!update.imu_stale_changed) return;
  if (update.imu_stale) {
    std::ostringstream text;
    text << "no IMU data on " << imu_topic_ << " covers the step to the scan at " << update.tracker.stamp
         << " s (missing, or a gap longer than imu/max_gap " << options_.tracker.prediction.imu.max_gap
         << " s); the rotation is predicted from "
         << (update.tracker.diagnostics.prediction == hglasm::PredictionSource::kOdometry
                 ? "the wheel odometry"
             : update.tracker.diagnostics.prediction == hglasm::PredictionSource::kConstantVelocity
                 ? "the recent motion"
                 : "nothing (no motion known yet)")
         << " until it returns";
    ROS_WARN_STREAM("[" << name_ << "] " << text.str());
  } else {
    ROS_INFO_STREAM("[" << name_ << "] IMU data on " << imu_topic_ << " again: the rotation is the IMU's");
  }
  std::lock_guard<std::mutex> lock(stats_mutex_);
  imu_stale_ = update.imu_stale;
}

bool LaserOdometry::waitForInputs(double stamp, double sweep) {
  // Wheels whose stamps run late are waited for that much longer: their pose of the scan's instant comes
  // with a later message.
  const double wait = options_.odometry_wait + std::max(0.0, pipeline_.odometryTimeOffset());
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(wait));
  std::unique_lock<std::mutex> lock(input_mutex_);
  while (true) {
    takeQueuedInputs();
    if (stop_) return false;
    if (pipeline_.inputsReadyFor(stamp, sweep)) return true;
    if (input_cv_.wait_until(lock, deadline) == std::cv_status::timeout) {
      takeQueuedInputs();
      // Odometry that stopped (or lags by more than the wait) is not waited for again until it moves.
      pipeline_.inputsWaitTimedOut(stamp, sweep);
      return !stop_;
    }
  }
}

void LaserOdometry::warnThrottled(const std::string& key, const std::string& text, double period) {
  const ros::WallTime now = ros::WallTime::now();
  {
    std::lock_guard<std::mutex> lock(log_mutex_);
    auto it = last_warning_.find(key);
    if (it != last_warning_.end() && (now - it->second).toSec() < period) return;
    last_warning_[key] = now;
  }
  ROS_WARN_STREAM("[" << name_ << "] " << text);
}

bool LaserOdometry::ensureLaserMount(const std::string& laser_frame) {
  if (have_mount_ && laser_frame == mount_frame_) return true;
  LaserMount mount;
  if (laser_frame.empty() || laser_frame == options_.base_frame) {
    // The scans are in the base frame (or say nothing): no tf needed.
    if (laser_frame.empty()) {
      ROS_WARN_STREAM("[" << name_ << "] scans carry no frame_id; assuming the laser is at the origin of "
                          << options_.base_frame);
    }
  } else {
    geometry_msgs::TransformStamped transform;
    try {
      transform = tf_buffer_.lookupTransform(options_.base_frame, laser_frame, ros::Time(0));
    } catch (const tf2::TransformException& ex) {
      std::ostringstream text;
      text << "waiting for the transform " << options_.base_frame << " -> " << laser_frame
           << " (base_frame -> scan frame_id) on tf/tf_static; scans are held until it appears (" << ex.what()
           << ")";
      {
        std::lock_guard<std::mutex> lock(stats_mutex_);
        tf_wait_text_ = "waiting for tf " + options_.base_frame + " -> " + laser_frame;
        waiting_for_tf_ = true;
      }
      warnThrottled("tf_wait", text.str(), options_.tf_warn_period);
      return false;
    }
    std::string error;
    if (!laserMountFromTransform(transform.transform, &mount, &error)) {
      warnThrottled("tf_bad",
                    "unusable transform " + options_.base_frame + " -> " + laser_frame + ": " + error,
                    options_.tf_warn_period);
      std::lock_guard<std::mutex> lock(stats_mutex_);
      tf_wait_text_ = "unusable tf " + options_.base_frame + " -> " + laser_frame;
      waiting_for_tf_ = true;
      return false;
    }
  }
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    waiting_for_tf_ = false;
  }
  have_mount_ = true;
  mount_frame_ = laser_frame;
  pipeline_.setLaserMount(mount.base_to_laser, mount.upside_down);
  ROS_INFO_STREAM("[" << name_ << "] scan frame \"" << laser_frame << "\" at x " << mount.base_to_laser.x
                      << " m, y " << mount.base_to_laser.y << " m, yaw " << mount.base_to_laser.theta
                      << " rad in \"" << options_.base_frame << "\""
                      << (mount.upside_down ? ", upside down (scans mirrored)" : ""));
  if (mount.tilt > 0.05) {
    ROS_WARN_STREAM("[" << name_ << "] the laser's scan plane is tilted by " << mount.tilt
                        << " rad from the base plane; its planar projection is approximate");
  }
  return true;
}

void LaserOdometry::workerLoop() {
  while (true) {
    sensor_msgs::LaserScanConstPtr msg;
    {
      std::unique_lock<std::mutex> lock(input_mutex_);
      input_cv_.wait(lock, [this] { return stop_ || !scans_.empty(); });
      if (stop_) return;
      msg = scans_.front();
      scans_.pop_front();
    }
    if (!ensureLaserMount(stripLeadingSlash(msg->header.frame_id))) {
      // Hold the scan (at the front, unless the queue filled up meanwhile: then it is the oldest and
      // is dropped) and retry shortly.
      std::unique_lock<std::mutex> lock(input_mutex_);
      if (scans_.size() < static_cast<std::size_t>(options_.queue_size)) {
        scans_.push_front(msg);
      } else {
        ++dropped_scans_;
      }
      input_cv_.wait_for(lock, std::chrono::duration<double>(kTfRetrySeconds), [this] { return stop_; });
      if (stop_) return;
      continue;
    }
    const double sweep =
        hglasm::scanSweepTime(msg->time_increment, msg->ranges.size(), pipeline_.conversion());
    if (!waitForInputs(msg->header.stamp.toSec(), sweep)) return;
    processScan(*msg);
  }
}

void LaserOdometry::processScan(const sensor_msgs::LaserScan& msg) {
  const double stamp = msg.header.stamp.toSec();
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = threadCpuMs();

  std::vector<hglasm::Pose2D> population;
  const bool want_population = options_.publish_population && population_pub_.getNumSubscribers() > 0;
  const hglasm::RangeScan ranges = rangeScanFromMsg(msg);
  const hglasm::PipelineUpdate result =
      pipeline_.processScan(stamp, ranges, want_population ? &population : nullptr);
  const hglasm::TrackerUpdate& update = result.tracker;
  if (result.scan_error_changed) {
    // One message per change of state, not per scan.
    if (result.scan_error != hglasm::ScanError::kNone) {
      ROS_WARN_STREAM("[" << name_ << "] unusable scan (" << hglasm::toString(result.scan_error)
                          << "); integrating the prediction until scans are valid again");
    } else {
      ROS_INFO_STREAM("[" << name_ << "] scans are valid again");
    }
  }
  if (update.stale) {
    warnThrottled("stale scan", update.warning + " (counted in diagnostics)", kStaleWarnPeriod);
  } else if (!update.warning.empty()) {
    ROS_WARN_STREAM("[" << name_ << "] " << update.warning);
  }
  reportImuState(result);
  if (update.reset) path_.clear();

  publish(msg, result, msSince(start));
  if (want_population && update.matched) publishPopulation(msg.header.stamp, update, population);
  publishLocalMap(msg.header.stamp);

  ScanRecord record;
  record.time = ros::WallTime::now();
  record.cpu_ms = threadCpuMs() - cpu_start;
  record.matched = update.matched;
  record.fallback = update.fallback;
  std::lock_guard<std::mutex> lock(stats_mutex_);
  input_counts_ = pipeline_.inputCounts();
  time_offset_ = update.diagnostics.odometry_time_offset;
  time_offset_estimate_ = update.diagnostics.odometry_time_offset_estimate;
  if (update.matched) {
    degeneracy_ = update.diagnostics.degeneracy;
    weakest_direction_ = update.diagnostics.weakest_direction;
  }
  noise_scale_ = update.diagnostics.learned.wheel_noise;
  if (update.stale) return;  // not processed: not a scan of the rate or failure statistics
  ++scans_processed_;
  if (update.fallback) ++fallbacks_;
  if (update.reset) ++resets_;
  records_.push_back(record);
  while (!records_.empty() && (record.time - records_.front().time).toSec() > options_.diagnostics.window) {
    records_.pop_front();
  }
}

void LaserOdometry::publish(const sensor_msgs::LaserScan& msg, const hglasm::PipelineUpdate& result,
                            double total_ms) {
  if (result.tracker.published) publishPose(msg.header.stamp, result.tracker);
  std::uint32_t dropped_scans = 0;
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    dropped_scans = dropped_scans_;
  }
  match_pub_.publish(matchMsgFromUpdate(result, msg.header, total_ms, dropped_scans));
}

void LaserOdometry::publishPose(const ros::Time& stamp, const hglasm::TrackerUpdate& update) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = options_.odom_frame;
  const nav_msgs::Odometry odom = odometryMsgFromUpdate(update, header, options_.base_frame);
  odom_pub_.publish(odom);

  geometry_msgs::PoseWithCovarianceStamped pose_msg;
  pose_msg.header = header;
  pose_msg.pose = odom.pose;
  pose_pub_.publish(pose_msg);

  if (options_.publish_tf) {
    geometry_msgs::TransformStamped transform;
    transform.header = header;
    transform.child_frame_id = options_.base_frame;
    transform.transform = transformMsgFromPose2D(update.pose);
    tf_broadcaster_.sendTransform(transform);
  }

  if (options_.path_length > 0) {
    geometry_msgs::PoseStamped path_pose;
    path_pose.header = header;
    path_pose.pose = odom.pose.pose;
    path_.push_back(path_pose);
    while (path_.size() > static_cast<std::size_t>(options_.path_length)) path_.pop_front();
    if (path_pub_.getNumSubscribers() > 0) {
      nav_msgs::Path path;
      path.header = header;
      path.poses.assign(path_.begin(), path_.end());
      path_pub_.publish(path);
    }
  }
}

void LaserOdometry::publishLocalMap(const ros::Time& stamp) {
  if (local_map_pub_.getNumSubscribers() == 0) return;  // nothing is built for nobody
  const hglasm::LocalMap& map = pipeline_.localMap();
  const bool resend = local_map_resend_.exchange(false);
  if (!resend && local_map_sent_ && map.revision() == local_map_revision_) return;
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = options_.odom_frame;
  local_map_pub_.publish(pointCloudMsgFromPoints(header, map.frame(), map.reference().points));
  local_map_sent_ = true;
  local_map_revision_ = map.revision();
}

void LaserOdometry::publishPopulation(const ros::Time& stamp, const hglasm::TrackerUpdate& update,
                                      const std::vector<hglasm::Pose2D>& population) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = options_.odom_frame;
  population_pub_.publish(populationMarkers(header, population, update.pose, update.diagnostics.guess));
}

void LaserOdometry::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const ros::WallTime now = ros::WallTime::now();
  std::size_t queued = 0;
  std::uint32_t dropped_total = 0;
  {
    std::lock_guard<std::mutex> lock(input_mutex_);
    queued = scans_.size();
    dropped_total = dropped_scans_;
  }
  std::lock_guard<std::mutex> lock(stats_mutex_);
  while (!records_.empty() && (now - records_.front().time).toSec() > options_.diagnostics.window) {
    records_.pop_front();
  }
  const std::size_t count = records_.size();
  double cpu_sum = 0.0, cpu_max = 0.0;
  // Every scan that should have given a laser estimate counts: a failed match, but also an empty or
  // all-invalid scan (a blinded or disconnected laser), whose motion came from the prediction alone.
  std::size_t matched = 0, failed = 0;
  for (const ScanRecord& record : records_) {
    cpu_sum += record.cpu_ms;
    cpu_max = std::max(cpu_max, record.cpu_ms);
    if (record.matched || record.fallback) ++matched;
    if (record.fallback) ++failed;
  }
  // Processing rate over the records in the window (wall clock: what the robot's computer sustains).
  const double span = count >= 2 ? (records_.back().time - records_.front().time).toSec() : 0.0;
  const double rate = span > 0.0 ? (count - 1) / span : 0.0;
  const double cpu_mean = count > 0 ? cpu_sum / count : 0.0;
  const double failure_ratio = matched > 0 ? static_cast<double>(failed) / matched : 0.0;

  status.add("scan rate (Hz)", rate);
  status.add("CPU per scan, mean (ms)", cpu_mean);
  status.add("CPU per scan, max (ms)", cpu_max);
  status.add("failure ratio", failure_ratio);
  status.add("scans received", scans_received_);
  status.add("scans processed", scans_processed_);
  status.add("fallbacks", fallbacks_);
  status.add("resets", resets_);
  status.add("clock jumps back (resets)", input_counts_.jumps_back);
  status.add("dropped scans", dropped_total);
  status.add("stale scans dropped", input_counts_.stale_scans);
  status.add("stale odometry samples dropped", input_counts_.stale_odometry);
  if (options_.tracker.prediction.use_imu) status.add("stale IMU samples dropped", input_counts_.stale_imu);
  if (options_.tracker.prediction.use_odometry) {
    status.add("odometry time offset (s)", time_offset_);
    status.add("odometry time offset, estimate (s)", time_offset_estimate_);
    status.add("odometry time offset",
               options_.tracker.learning.odometry_time_offset.estimate ? "learned" : "fixed");
  }
  status.add("degeneracy of the last match (min / max information)", degeneracy_);
  status.add("weakest direction of the last match (x, y, theta)",
             std::to_string(weakest_direction_.x()) + ", " + std::to_string(weakest_direction_.y()) + ", " +
                 std::to_string(weakest_direction_.z()));
  status.add("wheel noise scale learned (xy, theta)",
             std::to_string(noise_scale_.xy) + ", " + std::to_string(noise_scale_.theta));
  status.add("queued scans", queued);
  status.add("preset", options_.preset);
  if (options_.tracker.prediction.use_imu)
    status.add("IMU", imu_stale_ ? "stale: rotation predicted without it" : "in use");

  const bool scans_arriving =
      !last_scan_time_.isZero() && (now - last_scan_time_).toSec() <= options_.diagnostics.window;
  if (waiting_for_tf_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, tf_wait_text_);
  } else if (!scans_arriving) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   last_scan_time_.isZero() ? "no scans received yet" : "no scans received recently");
  } else if (matched > 0 && failure_ratio >= options_.diagnostics.error_failure_ratio) {
    status.summaryf(diagnostic_msgs::DiagnosticStatus::ERROR, "%.0f%% of scans failed to match",
                    100.0 * failure_ratio);
  } else if (matched > 0 && failure_ratio >= options_.diagnostics.warn_failure_ratio) {
    status.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%.0f%% of scans failed to match",
                    100.0 * failure_ratio);
  } else if (options_.tracker.prediction.use_imu && imu_stale_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "IMU stale or missing: rotation predicted without it");
  } else if (dropped_total > last_reported_drops_) {
    status.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                    "dropping scans: %u dropped so far (processing is slower than the input)", dropped_total);
  } else if (options_.diagnostics.min_rate > 0.0 && rate < options_.diagnostics.min_rate) {
    status.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "scan rate %.2f Hz below %.2f Hz", rate,
                    options_.diagnostics.min_rate);
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  }
  last_reported_drops_ = dropped_total;
}

}  // namespace hglasm_odometry
