#include "hglasm_odometry/core/odometry_pipeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hglasm_odometry/core/timing.h"

namespace hglasm {

ScanConversionOptions conversionForMount(ScanConversionOptions conversion, bool upside_down) {
  conversion.mirror = upside_down;
  return conversion;
}

const char* toString(SampleVerdict verdict) {
  switch (verdict) {
    case SampleVerdict::kTaken:
      return "taken";
    case SampleVerdict::kInvalid:
      return "invalid";
    case SampleVerdict::kStale:
      return "stale";
    case SampleVerdict::kNewTimeline:
      return "new_timeline";
  }
  return "unknown";
}

OdometryPipeline::OdometryPipeline(const TrackerOptions& options, bool wait_for_odometry)
    : tracker_(options),
      wait_for_inputs_(wait_for_odometry),
      conversion_(options.conversion),
      wheels_(options.reset_on_jump_back),
      imu_(options.reset_on_jump_back),
      scan_order_(options.reset_on_jump_back) {}

bool OdometryPipeline::setLaserMount(const Pose2D& base_to_laser, bool upside_down) {
  if (!base_to_laser.isFinite()) return false;
  conversion_ = conversionForMount(conversion_, upside_down);
  tracker_.setLaserMount(base_to_laser);
  return true;
}

SampleVerdict OdometryPipeline::addOdometry(double stamp, const Pose2D& pose) {
  if (!std::isfinite(stamp) || !pose.isFinite()) return SampleVerdict::kInvalid;
  const StampOrder::Verdict verdict = wheels_.take(stamp, scan_order_.newest() + odometryTimeOffset());
  if (verdict == StampOrder::Verdict::kStale) return SampleVerdict::kStale;
  if (verdict == StampOrder::Verdict::kJumpedBack) tracker_.clearOdometry();
  tracker_.addOdometry(stamp, pose);
  return verdict == StampOrder::Verdict::kJumpedBack ? SampleVerdict::kNewTimeline : SampleVerdict::kTaken;
}

SampleVerdict OdometryPipeline::addImu(double stamp, double value) {
  if (!tracker_.options().prediction.use_imu || !std::isfinite(stamp) || !std::isfinite(value)) {
    return SampleVerdict::kInvalid;
  }
  const StampOrder::Verdict verdict = imu_.take(stamp, scan_order_.newest());
  if (verdict == StampOrder::Verdict::kStale) return SampleVerdict::kStale;
  if (verdict == StampOrder::Verdict::kJumpedBack) tracker_.clearImu();
  tracker_.addImu(stamp, value);
  return verdict == StampOrder::Verdict::kJumpedBack ? SampleVerdict::kNewTimeline : SampleVerdict::kTaken;
}

InputCounts OdometryPipeline::inputCounts() const {
  InputCounts counts;
  counts.stale_scans = scan_order_.staleCount();
  counts.stale_odometry = wheels_.order.staleCount();
  counts.stale_imu = imu_.order.staleCount();
  counts.jumps_back = scan_order_.jumpsBack();
  return counts;
}

StampOrder::Verdict OdometryPipeline::InputFeed::take(double stamp, double needed_by_last_scan) {
  const StampOrder::Verdict verdict = order.take(stamp);
  const bool caught_up = verdict == StampOrder::Verdict::kInOrder && !(stamp < needed_by_last_scan);
  if (verdict == StampOrder::Verdict::kJumpedBack || caught_up) stalled = false;
  return verdict;
}

bool OdometryPipeline::wheelsReadyFor(double stamp) const {
  return !tracker_.options().prediction.use_odometry || !wait_for_inputs_ ||
         wheels_.readyFor(stamp + tracker_.odometryTimeOffset());
}

bool OdometryPipeline::imuReadyFor(double stamp) const {
  return !tracker_.options().prediction.use_imu || !wait_for_inputs_ || imu_.readyFor(stamp);
}

AwaitedStamps OdometryPipeline::awaitedFor(double stamp, double sweep) const {
  AwaitedStamps awaited;
  const bool dropped = stamp < scan_order_.newest() && !scan_order_.behind(stamp);
  if (dropped) return awaited;  // the time policy drops it: it waits for nothing
  if (!wheelsReadyFor(stamp)) awaited.wheels = stamp + tracker_.odometryTimeOffset();
  const double sweep_end = stamp + std::max(0.0, sweep);
  if (!imuReadyFor(sweep_end)) awaited.imu = sweep_end;
  return awaited;
}

void OdometryPipeline::inputsWaitTimedOut(double stamp, double sweep) {
  if (!wheelsReadyFor(stamp)) wheels_.stalled = true;
  if (!imuReadyFor(stamp + std::max(0.0, sweep))) imu_.stalled = true;
}

PipelineUpdate OdometryPipeline::staleScan(double stamp, double newest) const {
  PipelineUpdate update;
  update.tracker.stamp = stamp;
  update.tracker.stale = true;
  update.tracker.pose = tracker_.pose();
  std::ostringstream text;
  text << "scan stamped " << (newest - stamp) << " s before the last one processed: dropped";
  update.tracker.warning = text.str();
  update.imu_stale = imu_stale_;
  return update;
}

std::string OdometryPipeline::restartTimeline(double stamp, double newest) {
  std::ostringstream text;
  text << "scan time went back by " << (newest - stamp)
       << " s (more than time/reset_on_jump_back: a looped bag or a restarted clock)";
  // Inputs whose newest sample is still on the old timeline hold samples of other instants at the new
  // stamps: mixed with the new ones they would turn every prediction into a jump.
  if (wheels_.order.behind(stamp)) {
    tracker_.clearOdometry();
    wheels_.order.restart();
    wheels_.stalled = false;
  }
  if (imu_.order.behind(stamp)) {
    tracker_.clearImu();
    imu_.order.restart();
    imu_.stalled = false;
  }
  reset();
  text << "; odometry reset to the origin";
  return text.str();
}

PipelineUpdate OdometryPipeline::processScan(double stamp, const RangeScan& ranges,
                                             std::vector<Pose2D>* population) {
  PipelineUpdate update;
  std::string timeline_warning;
  if (std::isfinite(stamp)) {
    const double newest = scan_order_.newest();
    const StampOrder::Verdict verdict = scan_order_.take(stamp);
    if (verdict == StampOrder::Verdict::kStale) return staleScan(stamp, newest);
    update.jumped_back = verdict == StampOrder::Verdict::kJumpedBack;
    if (update.jumped_back) timeline_warning = restartTimeline(stamp, newest);
  }
  const double cpu_start = threadCpuMs();
  update.scan = scanFromRanges(ranges, conversion_, &update.scan_error);
  update.conversion_cpu_ms = threadCpuMs() - cpu_start;
  update.scan_error_changed = update.scan_error != scan_error_;
  scan_error_ = update.scan_error;

  // The local map's frame the scan is matched in (a keyframe may move it): the one the guess is relative to.
  const Pose2D map_frame = tracker_.localMap().frame();
  update.tracker = tracker_.processScan(stamp, update.scan, population);
  if (!timeline_warning.empty()) {
    update.tracker.warning =
        timeline_warning + (update.tracker.warning.empty() ? "" : "; " + update.tracker.warning);
  }
  const TrackerUpdate& result = update.tracker;
  if (result.matched) {
    // The tracker's own conjugation of the predicted base motion by the mount (moved by under a millimetre
    // since, if the lever arm is being learned).
    update.laser_guess = map_frame.inverse() * result.diagnostics.guess * tracker_.mountInUse();
  }
  if (tracker_.options().prediction.use_imu && result.published && !result.reset) {
    update.imu_stale = !result.diagnostics.rotation_from_imu;
    update.imu_stale_changed = update.imu_stale != imu_stale_;
    imu_stale_ = update.imu_stale;
  } else {
    update.imu_stale = imu_stale_;
  }
  return update;
}

void OdometryPipeline::reset() { tracker_.reset(); }

bool OdometryPipeline::setPose(double stamp, const Pose2D& pose, const Eigen::Matrix3d& covariance) {
  if (!tracker_.setPose(stamp, pose, covariance)) return false;
  return true;
}

}  // namespace hglasm
