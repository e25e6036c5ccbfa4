#include "hglasm_odometry/core/odometry_buffer.h"

#include <algorithm>
#include <cmath>

namespace hglasm {

bool OdometryBuffer::add(double stamp, const Pose2D& pose) {
  if (!std::isfinite(stamp) || !pose.isFinite()) return false;
  const auto later = std::upper_bound(samples_.begin(), samples_.end(), stamp,
                                      [](double t, const Sample& sample) { return t < sample.stamp; });
  samples_.insert(later, Sample{stamp, pose});
  prune();
  return true;
}

void OdometryBuffer::keepAround(double stamp, double margin) {
  if (!std::isfinite(stamp)) return;
  keep_from_ = stamp - std::abs(margin);
  keep_to_ = stamp + std::abs(margin);
}

void OdometryBuffer::prune() {
  if (samples_.size() <= 2) return;
  const auto first_at_or_after = [this](double t) {
    return std::lower_bound(samples_.begin(), samples_.end(), t,
                            [](const Sample& sample, double value) { return sample.stamp < value; });
  };
  // The recent span (at least the two newest samples), and the one kept around keep_from_..keep_to_ with
  // the samples that bracket it; everything else older than max_age goes.
  auto recent = std::min(first_at_or_after(samples_.back().stamp - max_age_), samples_.end() - 2);
  if (!std::isfinite(keep_to_)) {
    samples_.erase(samples_.begin(), recent);
    return;
  }
  auto kept_end = first_at_or_after(keep_to_);
  if (kept_end != samples_.end()) ++kept_end;
  if (kept_end < recent) recent = samples_.erase(kept_end, recent);
  auto kept_begin = first_at_or_after(keep_from_);
  if (kept_begin != samples_.begin()) --kept_begin;
  samples_.erase(samples_.begin(), std::min(kept_begin, recent));
}

double OdometryBuffer::largestGap(double from, double to) const {
  if (samples_.empty() || !(samples_.front().stamp <= from) || !(samples_.back().stamp >= to)) {
    return std::numeric_limits<double>::infinity();
  }
  auto it = std::upper_bound(samples_.begin(), samples_.end(), from,
                             [](double t, const Sample& sample) { return t < sample.stamp; });
  if (it != samples_.begin()) --it;  // the last sample at or before `from`
  double largest = 0.0;
  for (auto next = it + 1; next != samples_.end() && it->stamp < to; ++it, ++next) {
    largest = std::max(largest, next->stamp - it->stamp);
  }
  return largest;
}

double OdometryBuffer::largestTurnRate(double from, double to) const {
  if (samples_.empty() || !(samples_.front().stamp <= from) || !(samples_.back().stamp >= to)) {
    return std::numeric_limits<double>::infinity();
  }
  auto it = std::upper_bound(samples_.begin(), samples_.end(), from,
                             [](double t, const Sample& sample) { return t < sample.stamp; });
  if (it != samples_.begin()) --it;
  double largest = 0.0;
  for (auto next = it + 1; next != samples_.end() && it->stamp < to; ++it, ++next) {
    const double turn = std::abs(normalizeAngle(next->pose.theta - it->pose.theta));
    const double dt = next->stamp - it->stamp;
    largest = std::max(largest,
                       dt > 0.0 ? turn / dt : (turn > 0.0 ? std::numeric_limits<double>::infinity() : 0.0));
  }
  return largest;
}

double OdometryBuffer::newestStamp() const { return samples_.empty() ? 0.0 : samples_.back().stamp; }

bool OdometryBuffer::poseAt(double stamp, double max_extrapolation, Pose2D* pose, double* outside) const {
  if (samples_.empty() || !std::isfinite(stamp)) return false;
  if (outside) {
    *outside = std::max({0.0, samples_.front().stamp - stamp, stamp - samples_.back().stamp});
  }
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
