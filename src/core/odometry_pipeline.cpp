#include "hglasm_odometry/core/odometry_pipeline.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <sstream>

namespace hglasm {
namespace {

/// CPU time of the calling thread (process CPU where POSIX thread clocks are missing), milliseconds.
double threadCpuMs() {
#if defined(CLOCK_THREAD_CPUTIME_ID)
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return now.tv_sec * 1e3 + now.tv_nsec * 1e-6;
#else
  return 1e3 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
#endif
}

}  // namespace

ScanConversionOptions conversionForMount(ScanConversionOptions conversion, bool upside_down) {
  conversion.mirror = upside_down;
  return conversion;
}

OdometryPipeline::OdometryPipeline(const TrackerOptions& options, bool wait_for_odometry)
    : tracker_(options), wait_for_inputs_(wait_for_odometry), conversion_(options.conversion) {}

bool OdometryPipeline::setLaserMount(const Pose2D& base_to_laser, bool upside_down) {
  if (!base_to_laser.isFinite()) return false;
  base_to_laser_ = base_to_laser;
  conversion_ = conversionForMount(conversion_, upside_down);
  tracker_.setLaserMount(base_to_laser);
  return true;
}

bool OdometryPipeline::addOdometry(double stamp, const Pose2D& pose) {
  // The tracker's buffer rejects the same samples: the newest stamp must only count what it holds.
  if (!std::isfinite(stamp) || !pose.isFinite()) return false;
  tracker_.addOdometry(stamp, pose);
  wheels_.added(stamp, last_scan_stamp_);
  return true;
}

bool OdometryPipeline::addImu(double stamp, double value) {
  if (!tracker_.addImu(stamp, value)) return false;
  imu_.added(stamp, last_scan_stamp_);
  return true;
}

void OdometryPipeline::InputFeed::added(double stamp, double last_scan) {
  if (stamp > newest) newest = stamp;
  if (!(stamp < last_scan)) stalled = false;
}

bool OdometryPipeline::wheelsReadyFor(double stamp) const {
  return !tracker_.options().use_odometry || !wait_for_inputs_ || wheels_.readyFor(stamp);
}

bool OdometryPipeline::imuReadyFor(double stamp) const {
  return !tracker_.options().use_imu || !wait_for_inputs_ || imu_.readyFor(stamp);
}

bool OdometryPipeline::inputsReadyFor(double stamp, double sweep) const {
  return wheelsReadyFor(stamp) && imuReadyFor(stamp + std::max(0.0, sweep));
}

void OdometryPipeline::inputsWaitTimedOut(double stamp, double sweep) {
  if (!wheelsReadyFor(stamp)) wheels_.stalled = true;
  if (!imuReadyFor(stamp + std::max(0.0, sweep))) imu_.stalled = true;
}

std::string OdometryPipeline::checkGeometry(const RangeScan& ranges) {
  // The tracker compares beam counts only: a changed angular geometry with the same beam count would be
  // matched against a reference of other geometry. Make such a scan a keyframe.
  std::string warning;
  const bool increment_changed =
      have_geometry_ && ranges.ranges.size() == beam_count_ &&
      std::abs(ranges.angle_increment - angle_increment_) > 1e-6 * std::abs(angle_increment_) + 1e-9;
  if (increment_changed) {
    std::ostringstream text;
    text << "scan angle_increment changed from " << angle_increment_ << " to " << ranges.angle_increment
         << "; new keyframe";
    warning = text.str();
    tracker_.requestKeyframe();
  }
  have_geometry_ = true;
  beam_count_ = ranges.ranges.size();
  angle_increment_ = ranges.angle_increment;
  return warning;
}

PipelineUpdate OdometryPipeline::processScan(double stamp, const RangeScan& ranges,
                                             std::vector<Pose2D>* population) {
  PipelineUpdate update;
  if (std::isfinite(stamp)) last_scan_stamp_ = stamp;
  const double cpu_start = threadCpuMs();
  update.scan = scanFromRanges(ranges, conversion_, &update.scan_error);
  update.conversion_cpu_ms = threadCpuMs() - cpu_start;
  update.scan_error_changed = update.scan_error != scan_error_;
  scan_error_ = update.scan_error;
  // A broken scan says nothing reliable about the scanner's geometry.
  if (update.scan_error == ScanError::kNone) update.geometry_warning = checkGeometry(ranges);

  // The keyframe before this scan: the one the guess is relative to.
  const Pose2D keyframe_before = keyframe_pose_;
  update.tracker = tracker_.processScan(stamp, update.scan, population);
  const TrackerUpdate& result = update.tracker;
  if (result.matched) {
    // The tracker's own conjugation of the predicted base motion by the mount.
    update.laser_guess =
        base_to_laser_.inverse() * relativePose(keyframe_before, result.guess) * base_to_laser_;
  }
  if (result.new_keyframe) keyframe_pose_ = result.pose;
  if (tracker_.options().use_imu && result.published && !result.reset) {
    update.imu_stale = !result.rotation_from_imu;
    update.imu_stale_changed = update.imu_stale != imu_stale_;
    imu_stale_ = update.imu_stale;
  } else {
    update.imu_stale = imu_stale_;
  }
  return update;
}

void OdometryPipeline::reset() {
  tracker_.reset();
  keyframe_pose_ = Pose2D();
}

bool OdometryPipeline::setPose(double stamp, const Pose2D& pose, const Eigen::Matrix3d& covariance) {
  if (!tracker_.setPose(stamp, pose, covariance)) return false;
  keyframe_pose_ = tracker_.pose();
  return true;
}

}  // namespace hglasm
