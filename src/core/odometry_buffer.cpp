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
  // Outside the buffered span hold the nearest sample (for at most max_extrapolation seconds):
  // extrapolating from odometry samples that are often < 1 ms apart would amplify their noise.
  if (stamp <= samples_.front().stamp) {
    if (samples_.front().stamp - stamp > max_extrapolation) return false;
    *pose = samples_.front().pose;
    return true;
  }
  if (stamp >= samples_.back().stamp) {
    if (stamp - samples_.back().stamp > max_extrapolation) return false;
    *pose = samples_.back().pose;
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
