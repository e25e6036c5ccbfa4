#include "hglasm_odometry/core/time_offset_estimator.h"

#include <algorithm>
#include <cmath>

namespace hglasm {
namespace {

constexpr std::size_t kMaxPendingWindows = 100;  // while the wheels stall: older windows are dropped

}  // namespace

TimeOffsetEstimator::TimeOffsetEstimator(const TimeOffsetOptions& options)
    : options_(options), offset_(options.offset), estimate_(options.offset) {
  const std::size_t half = static_cast<std::size_t>(std::round(std::max(0.0, options_.max_offset) / kStep));
  heading_.assign(2 * half + 1, Sums());
}

double TimeOffsetEstimator::candidateOffset(std::size_t candidate) const {
  const double half = static_cast<double>(heading_.size() / 2);
  return (static_cast<double>(candidate) - half) * kStep;
}

void TimeOffsetEstimator::addScanPose(double stamp, const Pose2D& pose) {
  if (!options_.estimate || !std::isfinite(stamp) || !pose.isFinite()) return;
  const double span = stamp - start_.stamp;
  if (!have_start_ || !(span >= 0.0) || span > kMaxWindow) {
    start_ = StampedPose{stamp, pose};
    have_start_ = true;
    return;
  }
  if (span < kWindow) return;
  pending_.push_back(Window{start_.stamp, stamp, normalizeAngle(pose.theta - start_.pose.theta)});
  if (pending_.size() > kMaxPendingWindows) pending_.pop_front();
  start_ = StampedPose{stamp, pose};
}

bool TimeOffsetEstimator::update(const OdometryBuffer& wheels) {
  bool scored = false;
  while (!pending_.empty() && !wheels.empty() &&
         wheels.newestStamp() >= pending_.front().to + options_.max_offset) {
    score(pending_.front(), wheels);
    pending_.pop_front();
    scored = true;
  }
  return scored && decide();
}

void TimeOffsetEstimator::score(const Window& window, const OdometryBuffer& wheels) {
  // Where the wheels are sampled coarsely (only with the scans, a pause, a burst), shifting them means
  // interpolating across their gaps: no measure of their timing.
  const double reach = options_.max_offset + 0.5 * kStep;
  if (wheels.largestGap(window.from - reach, window.to + reach) > kMaxSampleGap) return;
  // A jump of the wheels' frame (a driver restart, a glitch) inside the window would be "explained" by
  // whichever shift moves it out: such windows say nothing about the timing.
  if (wheels.largestTurnRate(window.from - reach, window.to + reach) > kMaxWheelTurnRate) return;
  // Every candidate must see the window, or their costs would not compare.
  std::vector<double> turns(heading_.size());
  for (std::size_t k = 0; k < turns.size(); ++k) {
    const double shift = candidateOffset(k);
    Pose2D from, to;
    if (!wheels.poseAt(window.from + shift, 0.0, &from) || !wheels.poseAt(window.to + shift, 0.0, &to))
      return;
    turns[k] = normalizeAngle(to.theta - from.theta);
  }
  const double forget = std::exp2(-1.0 / kHalfLife);
  const auto add = [forget](Sums* sums, double scans, double wheels_value) {
    sums->ss = forget * sums->ss + scans * scans;
    sums->sw = forget * sums->sw + scans * wheels_value;
    sums->ww = forget * sums->ww + wheels_value * wheels_value;
  };
  for (std::size_t k = 0; k < turns.size(); ++k) add(&heading_[k], window.turn, turns[k]);
  weight_ = forget * weight_ + 1.0;
}

std::size_t TimeOffsetEstimator::nearest(double offset) const {
  const double half = static_cast<double>(heading_.size() / 2);
  return static_cast<std::size_t>(
      std::clamp(std::round(offset / kStep) + half, 0.0, static_cast<double>(heading_.size() - 1)));
}

double TimeOffsetEstimator::cost(std::size_t candidate) const { return heading_[candidate].cost(); }

bool TimeOffsetEstimator::best(double* offset, double* best_cost) const {
  if (heading_.empty() || !(weight_ > 0.0)) return false;
  std::size_t k = 0;
  for (std::size_t i = 1; i < heading_.size(); ++i) {
    if (cost(i) < cost(k)) k = i;
  }
  *offset = candidateOffset(k);
  *best_cost = cost(k);
  if (k > 0 && k + 1 < heading_.size()) {
    // The parabola through the minimum and its neighbours: sub-step precision.
    const double before = cost(k - 1), after = cost(k + 1);
    const double curvature = before - 2.0 * *best_cost + after;
    if (curvature > 0.0) *offset += std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5) * kStep;
  }
  return true;
}

bool TimeOffsetEstimator::decide() {
  double candidate = 0.0, candidate_cost = 0.0;
  if (!options_.estimate || !best(&candidate, &candidate_cost)) return false;
  estimate_ = candidate;
  const double target = std::abs(candidate) < kMinOffset ? 0.0 : candidate;
  if (weight_ < kMinWindows || !(std::abs(target - offset_) >= kStep)) return false;
  // The residual variance per window at the best candidate turns the costs into a log-likelihood ratio.
  const double variance = std::max(candidate_cost / weight_, 1e-12);
  const double log_ratio = 0.5 * (cost(nearest(offset_)) - cost(nearest(target))) / variance;
  if (!(log_ratio > 0.5 * kEvidenceSigmas * kEvidenceSigmas)) return false;
  offset_ = target;
  return true;
}

}  // namespace hglasm
