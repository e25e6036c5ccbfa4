#include "hglasm_odometry/ros/laser_odometry.h"

#include <algorithm>
#include <chrono>
#include <sstream>
#include <utility>

#include <pthread.h>

#include <geometry_msgs/TransformStamped.h>

#include "hglasm_odometry/core/timing.h"

namespace hglasm_odometry {
namespace {

/// Seconds on the clock of the throttling, the mounts' retries and the diagnostics (monotonic).
double steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Subscriber queues only need to absorb bursts until the callback moves the message into the bounded
/// queue (callbacks are cheap); they are not where scans are dropped.
constexpr int kScanSubscriberQueue = 50;
constexpr int kOdomSubscriberQueue = 200;
constexpr int kImuSubscriberQueue = 1000;
constexpr double kTfRetrySeconds = 0.05;   // wall time between tf lookups while a mount is missing
constexpr double kStaleWarnPeriod = 10.0;  // seconds between warnings about inputs stamped out of order
constexpr char kWorkerThreadName[] = "laser_odometry";

InputQueueLimits queueLimits(const LaserOdometryOptions& options) {
  InputQueueLimits limits;
  limits.scans = static_cast<std::size_t>(options.queue_size);
  return limits;
}

DiagnosticsSettings diagnosticsSettings(const LaserOdometryOptions& options) {
  DiagnosticsSettings settings;
  settings.thresholds = options.diagnostics;
  settings.preset = options.preset;
  settings.use_odometry = options.tracker.prediction.use_odometry;
  settings.use_imu = options.tracker.prediction.use_imu;
  settings.time_offset_learned = options.tracker.learning.odometry_time_offset.estimate;
  return settings;
}

std::uint8_t statusLevel(DiagnosticsReport::Level level) {
  switch (level) {
    case DiagnosticsReport::Level::kOk:
      return diagnostic_msgs::DiagnosticStatus::OK;
    case DiagnosticsReport::Level::kWarn:
      return diagnostic_msgs::DiagnosticStatus::WARN;
    case DiagnosticsReport::Level::kError:
      return diagnostic_msgs::DiagnosticStatus::ERROR;
  }
  return diagnostic_msgs::DiagnosticStatus::ERROR;
}

const char* predictionName(hglasm::PredictionSource source) {
  switch (source) {
    case hglasm::PredictionSource::kOdometry:
      return "the wheel odometry";
    case hglasm::PredictionSource::kConstantVelocity:
      return "the recent motion";
    case hglasm::PredictionSource::kNone:
      return "nothing (no motion known yet)";
  }
  return "nothing (no motion known yet)";
}

}  // namespace

LaserOdometry::LaserOdometry(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                             const LaserOdometryOptions& options)
    : options_(options),
      name_(private_nh.getNamespace()),
      imu_topic_(nh.resolveName("imu")),
      odom_topic_(nh.resolveName("odom")),
      nh_(nh),
      private_nh_(private_nh),
      queue_(queueLimits(options)),
      pipeline_(options.tracker, options.odometry_wait > 0.0),
      laser_mount_(0.0, 1),
      imu_mounts_(kTfRetrySeconds),
      output_(private_nh_, options, [this] { queue_.requestLocalMap(); }),
      diagnostics_settings_(diagnosticsSettings(options)),
      tf_listener_(tf_buffer_),
      diagnostics_(nh, private_nh, private_nh.getNamespace()) {
  // Outputs first (output_), inputs last: nothing arrives before there is somewhere to publish it.
  reset_service_ = private_nh_.advertiseService("reset", &LaserOdometry::resetCallback, this);
  set_pose_service_ = private_nh_.advertiseService("set_pose", &LaserOdometry::setPoseCallback, this);

  diagnostics_.setHardwareID("none");
  diagnostics_.add("laser odometry", this, &LaserOdometry::diagnose);
  diagnostics_timer_ =
      private_nh_.createWallTimer(ros::WallDuration(options_.diagnostics.period),
                                  [this](const ros::WallTimerEvent&) { diagnostics_.force_update(); });

  worker_ = std::thread(&LaserOdometry::workerLoop, this);
  subscribe();
}

void LaserOdometry::subscribe() {
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
  queue_.stop();
  if (worker_.joinable()) worker_.join();
}

// ------------------------------------------------------------------------------------------ spinner threads

void LaserOdometry::scanCallback(const sensor_msgs::LaserScanConstPtr& msg) {
  queue_.pushScan(msg, steadySeconds());
}

bool LaserOdometry::resetCallback(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  queue_.requestReset();
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
  queue_.requestPose(request);
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

void LaserOdometry::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const ScanQueueCounts scans = queue_.scanCounts();
  DiagnosticsReport report;
  {
    std::lock_guard<std::mutex> lock(statistics_mutex_);
    report = hglasm_odometry::diagnose(statistics_, scans, diagnostics_settings_, steadySeconds(),
                                       last_reported_drops_);
  }
  last_reported_drops_ = scans.dropped;
  for (const auto& [key, value] : report.values) status.add(key, value);
  status.summary(statusLevel(report.level), report.summary);
}

// ------------------------------------------------------------------------------------------ the worker

void LaserOdometry::workerLoop() {
  // Named so that top -H, perf and scripts/node_cpu_monitor.py tell it from roscpp's threads (at most 15
  // characters).
  pthread_setname_np(pthread_self(), kWorkerThreadName);
  while (std::optional<sensor_msgs::LaserScanConstPtr> scan = queue_.waitForScan()) {
    const sensor_msgs::LaserScan& msg = **scan;
    if (!laserMountReady(msg.header.frame_id)) {
      // Held at the front (dropped instead if the queue filled up meanwhile) and retried shortly.
      if (!queue_.holdScan(std::move(*scan), kTfRetrySeconds)) return;
      continue;
    }
    const double sweep = hglasm::scanSweepTime(msg.time_increment, msg.ranges.size(), pipeline_.conversion());
    if (!waitForInputs(msg.header.stamp.toSec(), sweep)) return;
    processScan(msg);
  }
}

bool LaserOdometry::waitForInputs(double stamp, double sweep) {
  // Wheels whose stamps run late are waited for that much longer: their pose of the scan's instant comes
  // with a later message.
  const double wait = options_.odometry_wait + std::max(0.0, pipeline_.odometryTimeOffset());
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(wait));
  while (takeInputs()) {
    const hglasm::AwaitedStamps awaited = pipeline_.awaitedFor(stamp, sweep);
    if (awaited.nothing()) return true;  // inputsReadyFor
    if (!queue_.waitForInputs(deadline, awaited)) {
      if (!takeInputs()) return false;
      // Odometry that stopped (or lags by more than the wait) is not waited for again until it moves.
      pipeline_.inputsWaitTimedOut(stamp, sweep);
      return true;
    }
  }
  return false;
}

bool LaserOdometry::takeInputs() {
  const bool running = queue_.take(&inputs_);
  if (inputs_.reset) pipeline_.reset();
  if (inputs_.pose && !pipeline_.setPose(inputs_.pose->stamp, inputs_.pose->pose, inputs_.pose->covariance)) {
    ROS_WARN_STREAM("[" << name_ << "] the pose to continue from was refused by the tracker");
  }
  for (std::size_t i = 0; i < inputs_.odometry.size(); ++i) addOdometry(*inputs_.odometry[i]);
  inputs_.odometry.clear();
  for (std::size_t i = 0; i < inputs_.imu.size(); ++i) addImu(*inputs_.imu[i]);
  inputs_.imu.clear();
  return running;
}

void LaserOdometry::addOdometry(const nav_msgs::Odometry& msg) {
  hglasm::Pose2D pose;
  if (!pose2DFromOdometryMsg(msg, &pose)) {
    warnThrottled("odom_nan", "wheel odometry message with a non-finite pose ignored", 10.0);
    return;
  }
  const std::string_view child_frame = withoutLeadingSlash(msg.child_frame_id);
  if (!child_frame.empty() && child_frame != options_.base_frame && !warned_odom_child_frame_) {
    warned_odom_child_frame_ = true;  // once: the configuration will not change by itself
    ROS_WARN_STREAM("[" << name_ << "] wheel odometry on " << odom_topic_ << " is of frame \"" << child_frame
                        << "\", not of base_frame \"" << options_.base_frame
                        << "\"; it is used as the motion of base_frame anyway");
  }
  reportSample(false, pipeline_.addOdometry(msg.header.stamp.toSec(), pose));
}

void LaserOdometry::addImu(const sensor_msgs::Imu& msg) {
  geometry_msgs::Quaternion mount;
  if (!imuMount(withoutLeadingSlash(msg.header.frame_id), &mount)) return;
  double value = 0.0;
  std::string error;
  if (!imuValueFromMsg(msg, mount, options_.tracker.prediction.imu.use_orientation, &value, &error)) {
    warnThrottled("imu_bad", "IMU sample on " + imu_topic_ + " ignored: " + error, 10.0);
    return;
  }
  reportSample(true, pipeline_.addImu(msg.header.stamp.toSec(), value));
}

bool LaserOdometry::imuMount(std::string_view frame, geometry_msgs::Quaternion* rotation) {
  if (frame.empty() || frame == options_.base_frame) {
    if (frame.empty() && !warned_imu_frame_) {
      warned_imu_frame_ = true;
      ROS_WARN_STREAM("[" << name_ << "] IMU messages on " << imu_topic_
                          << " carry no frame_id; assuming the IMU is aligned with " << options_.base_frame);
    }
    *rotation = geometry_msgs::Quaternion();
    rotation->w = 1.0;
    return true;
  }
  const auto lookup = [this](std::string_view imu_frame, geometry_msgs::Quaternion* found) {
    const std::string frame_id(imu_frame);
    try {
      *found = tf_buffer_.lookupTransform(options_.base_frame, frame_id, ros::Time(0)).transform.rotation;
      return true;
    } catch (const tf2::TransformException& ex) {
      warnThrottled("imu_tf",
                    "IMU samples dropped: no transform " + options_.base_frame + " -> " + frame_id +
                        " (base_frame -> the IMU's frame_id) on tf yet (" + ex.what() + ")",
                    options_.tf_warn_period);
      return false;
    }
  };
  return imu_mounts_.find(frame, steadySeconds(), lookup, rotation) !=
         decltype(imu_mounts_)::Result::kMissing;
}

bool LaserOdometry::laserMountReady(const std::string& frame_id) {
  const std::string_view frame = withoutLeadingSlash(frame_id);
  LaserMount mount;
  const auto lookup = [this](std::string_view laser_frame, LaserMount* found) {
    return lookupLaserMount(laser_frame, found);
  };
  switch (laser_mount_.find(frame, steadySeconds(), lookup, &mount)) {
    case MountCache<LaserMount>::Result::kCached:
      return true;
    case MountCache<LaserMount>::Result::kFound:
      useLaserMount(frame, mount);
      return true;
    case MountCache<LaserMount>::Result::kMissing:
      return false;
  }
  return false;
}

bool LaserOdometry::lookupLaserMount(std::string_view frame, LaserMount* mount) {
  *mount = LaserMount();
  if (frame.empty() || frame == options_.base_frame) {
    // The scans are in the base frame (or say nothing): no tf needed.
    if (frame.empty()) {
      ROS_WARN_STREAM("[" << name_ << "] scans carry no frame_id; assuming the laser is at the origin of "
                          << options_.base_frame);
    }
    return true;
  }
  const std::string laser_frame(frame);
  geometry_msgs::TransformStamped transform;
  try {
    transform = tf_buffer_.lookupTransform(options_.base_frame, laser_frame, ros::Time(0));
  } catch (const tf2::TransformException& ex) {
    std::ostringstream text;
    text << "waiting for the transform " << options_.base_frame << " -> " << laser_frame
         << " (base_frame -> scan frame_id) on tf/tf_static; scans are held until it appears (" << ex.what()
         << ")";
    setTfWait("waiting for tf " + options_.base_frame + " -> " + laser_frame);
    warnThrottled("tf_wait", text.str(), options_.tf_warn_period);
    return false;
  }
  std::string error;
  if (!laserMountFromTransform(transform.transform, mount, &error)) {
    warnThrottled("tf_bad", "unusable transform " + options_.base_frame + " -> " + laser_frame + ": " + error,
                  options_.tf_warn_period);
    setTfWait("unusable tf " + options_.base_frame + " -> " + laser_frame);
    return false;
  }
  return true;
}

void LaserOdometry::useLaserMount(std::string_view frame, const LaserMount& mount) {
  setTfWait(std::nullopt);
  pipeline_.setLaserMount(mount.base_to_laser, mount.upside_down);
  ROS_INFO_STREAM("[" << name_ << "] scan frame \"" << frame << "\" at x " << mount.base_to_laser.x
                      << " m, y " << mount.base_to_laser.y << " m, yaw " << mount.base_to_laser.theta
                      << " rad in \"" << options_.base_frame << "\""
                      << (mount.upside_down ? ", upside down (scans mirrored)" : ""));
  if (mount.tilt > 0.05) {
    ROS_WARN_STREAM("[" << name_ << "] the laser's scan plane is tilted by " << mount.tilt
                        << " rad from the base plane; its planar projection is approximate");
  }
}

void LaserOdometry::processScan(const sensor_msgs::LaserScan& msg) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = hglasm::threadCpuMs();
  const bool with_population = output_.populationWanted();
  rangeScanFromMsg(msg, &ranges_);
  const hglasm::PipelineUpdate result =
      pipeline_.processScan(msg.header.stamp.toSec(), ranges_, with_population ? &population_ : nullptr);
  reportScan(result);
  publish(msg.header, result, with_population, hglasm::millisecondsSince(start));
  recordScan(result.tracker, hglasm::threadCpuMs() - cpu_start);
}

void LaserOdometry::publish(const std_msgs::Header& scan, const hglasm::PipelineUpdate& result,
                            bool with_population, double total_ms) {
  const hglasm::TrackerUpdate& update = result.tracker;
  if (update.reset) output_.restartPath();
  if (update.published) output_.publishEstimate(scan.stamp, update);
  if (output_.matchWanted()) output_.publishMatch(scan, result, total_ms, queue_.droppedScans());
  if (with_population && update.matched) output_.publishPopulation(scan.stamp, update, population_);
  if (output_.localMapWanted()) {
    output_.publishLocalMap(scan.stamp, pipeline_.localMap(), queue_.takeLocalMapRequest());
  }
}

void LaserOdometry::reportScan(const hglasm::PipelineUpdate& result) {
  if (result.scan_error_changed) {
    // One message per change of state, not per scan.
    if (result.scan_error != hglasm::ScanError::kNone) {
      ROS_WARN_STREAM("[" << name_ << "] unusable scan (" << hglasm::toString(result.scan_error)
                          << "); integrating the prediction until scans are valid again");
    } else {
      ROS_INFO_STREAM("[" << name_ << "] scans are valid again");
    }
  }
  const hglasm::TrackerUpdate& update = result.tracker;
  if (update.stale) {
    warnThrottled("stale scan", update.warning + " (counted in diagnostics)", kStaleWarnPeriod);
  } else if (!update.warning.empty()) {
    ROS_WARN_STREAM("[" << name_ << "] " << update.warning);
  }
  reportImuState(result);
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
    ROS_WARN_STREAM("[" << name_ << "] no IMU data on " << imu_topic_ << " covers the step to the scan at "
                        << update.tracker.stamp << " s (missing, or a gap longer than imu/max_gap "
                        << options_.tracker.prediction.imu.max_gap << " s); the rotation is predicted from "
                        << predictionName(update.tracker.diagnostics.prediction) << " until it returns");
  } else {
    ROS_INFO_STREAM("[" << name_ << "] IMU data on " << imu_topic_ << " again: the rotation is the IMU's");
  }
  std::lock_guard<std::mutex> lock(statistics_mutex_);
  statistics_.imu_stale = update.imu_stale;
}

void LaserOdometry::recordScan(const hglasm::TrackerUpdate& update, double cpu_ms) {
  ScanRecord record;
  record.time = steadySeconds();
  record.cpu_ms = cpu_ms;
  record.matched = update.matched;
  record.fallback = update.fallback;
  const hglasm::InputCounts counts = pipeline_.inputCounts();
  std::lock_guard<std::mutex> lock(statistics_mutex_);
  statistics_.add(record, update, counts, options_.diagnostics.window);
}

void LaserOdometry::setTfWait(std::optional<std::string> text) {
  std::lock_guard<std::mutex> lock(statistics_mutex_);
  statistics_.tf_wait = std::move(text);
}

void LaserOdometry::warnThrottled(const std::string& key, const std::string& text, double period) {
  if (log_throttle_.allow(key, steadySeconds(), period)) ROS_WARN_STREAM("[" << name_ << "] " << text);
}

}  // namespace hglasm_odometry
