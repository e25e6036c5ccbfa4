#include "hglasm_odometry/core/odometry_buffer.h"

#include <algorithm>
#include <cmath>

namespace hglasm {

bool OdometryBuffer::add(double stamp, const Pose2D& pose) {
  if (!std::isfinite(stamp) || !pose.isFinite()) return false;
  const auto later = std::upper_bound(samples_.begin(), samples_.end(), stamp,
                                      [](double t, const Sample& sample) { return t < sample.stamp; });
  samples_.insert(later, Sample{stamp, pose});
  const double oldest_kept = samples_.back().stamp - max_age_;
  while (samples_.size() > 2 && samples_.front().stamp < oldest_kept) samples_.pop_front();
  return true;
}

double OdometryBuffer::newestStamp() const { return samples_.empty() ? 0.0 : samples_.back().stamp; }

bool OdometryBuffer::poseAt(double stamp, double max_extrapolation, Pose2D* pose) const {
  if (samples_.empty() || !std::isfinite(stamp)) return false;
  // Before the buffered span hold the oldest sample (for at most max_extrapolation seconds).
  if (stamp <= samples_.front().stamp) {
    if (samples_.front().stamp - stamp > max_extrapolation) return false;
    *pose = samples_.front().pose;
    return true;
  }
  if (stamp >= samples_.back().stamp) {
    const Sample& newest = samples_.back();
    const double ahead = stamp - newest.stamp;
    if (ahead > max_extrapolation) return false;
    // Extrapolate with the odometry's own velocity, measured over at least kMinVelocityBaseline: samples
    // often come in pairs < 1 ms apart, whose difference is noise, not velocity.
    for (auto it = samples_.rbegin() + 1; it != samples_.rend(); ++it) {
      const double baseline = newest.stamp - it->stamp;
      if (baseline < kMinVelocityBaseline) continue;
      if (baseline > kMaxVelocityBaseline) break;
      *pose = interpolate(it->pose, newest.pose, 1.0 + ahead / baseline);
      return true;
    }
    *pose = newest.pose;  // no usable baseline: hold
    return true;
  }
  const auto upper = std::upper_bound(samples_.begin(), samples_.end(), stamp,
                                      [](double t, const Sample& sample) { return t < sample.stamp; });
  const Sample& a = *(upper - 1);
  const Sample& b = *upper;
  const double span = b.stamp - a.stamp;  // > 0: a.stamp < stamp < b.stamp
  *pose = interpolate(a.pose, b.pose, (stamp - a.stamp) / span);
  return true;
}

}  // namespace hglasm
