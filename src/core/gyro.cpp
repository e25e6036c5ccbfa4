#include "hglasm_odometry/core/gyro.h"

#include <algorithm>
#include <cmath>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {
namespace {

double square(double value) { return value * value; }

}  // namespace

double gyroRotationVariance(const GyroOptions& options, double angle, double dt, double bias_variance) {
  const double elapsed = std::isfinite(dt) ? std::max(0.0, dt) : 0.0;
  const double turned = std::isfinite(angle) ? std::abs(angle) : 0.0;
  const double bias =
      std::isfinite(bias_variance) ? std::max(0.0, bias_variance) : square(options.bias_sigma);
  const double variance = square(options.angle_random_walk) * elapsed + bias * square(elapsed) +
                          square(options.scale_error * turned);
  return std::max(variance, 1e-12);  // a covariance must stay invertible
}

GyroBiasEstimator::GyroBiasEstimator(const GyroOptions& options) : options_(options) { reset(); }

void GyroBiasEstimator::reset() {
  bias_ = 0.0;
  variance_ = square(options_.bias_sigma);
  have_stamp_ = false;
  mean_sigmas_ = mean_bias_error_ = 0.0;
}

bool GyroBiasEstimator::update(double predicted, double measured, double measured_variance, double dt,
                               double stamp) {
  if (!options_.estimate_bias || !std::isfinite(predicted) || !std::isfinite(measured) ||
      !std::isfinite(measured_variance) || measured_variance < 0.0 || !std::isfinite(dt) || !(dt > 0.0) ||
      !std::isfinite(stamp)) {
    return false;
  }
  const double elapsed = have_stamp_ ? std::max(dt, stamp - last_stamp_) : dt;
  last_stamp_ = stamp;
  have_stamp_ = true;
  variance_ += square(options_.bias_random_walk) * elapsed;
  // The step's innovation is the bias error times dt, plus the gyro's white and scale noise and the scans'.
  const double innovation = normalizeAngle(predicted - measured);
  const double noise =
      square(options_.angle_random_walk) * dt + square(options_.scale_error * measured) + measured_variance;
  const double expected = variance_ * dt * dt + noise;
  if (!(expected > 0.0)) return false;
  const double gate = kGate * std::sqrt(expected);
  const double gain = variance_ * dt / expected;
  bias_ += gain * std::clamp(innovation, -gate, gate);
  variance_ = std::max(0.0, (1.0 - gain * dt) * variance_);
  // Innovations that keep leaning one way (their recent mean, in sigmas, far from 0) say the bias moved
  // faster than bias_random_walk allows (an IMU that recalibrated, a warming sensor): widen the variance
  // to the bias error they show, and the next steps follow it.
  const double weight = 1.0 / kInnovationMemory;
  mean_sigmas_ = (1.0 - weight) * mean_sigmas_ + weight * innovation / std::sqrt(expected);
  mean_bias_error_ = (1.0 - weight) * mean_bias_error_ + weight * innovation / dt;
  if (std::abs(mean_sigmas_) > kDriftSigmas) {
    variance_ = std::max(variance_, square(mean_bias_error_));
    mean_sigmas_ = mean_bias_error_ = 0.0;
  }
  return true;
}

GyroBuffer::GyroBuffer(const GyroOptions& options) : options_(options) {}

bool GyroBuffer::add(double stamp, double value) {
  if (!std::isfinite(stamp) || !std::isfinite(value)) return false;
  const auto later = std::upper_bound(samples_.begin(), samples_.end(), stamp,
                                      [](double t, const Sample& sample) { return t < sample.stamp; });
  samples_.insert(later, Sample{stamp, value});
  if (samples_.size() > kMaxSamples) samples_.pop_front();
  return true;
}

void GyroBuffer::forgetBefore(double stamp) {
  while (samples_.size() > 1 && samples_[1].stamp <= stamp) samples_.pop_front();
}

double GyroBuffer::valueAt(double stamp) const {
  const auto beyond = [this, stamp](const Sample& end, const Sample& inner) {
    // The rate is held; the yaw goes on at the end segment's rate.
    if (!options_.use_orientation || end.stamp == inner.stamp) return end.value;
    return end.value +
           (stamp - end.stamp) * normalizeAngle(end.value - inner.value) / (end.stamp - inner.stamp);
  };
  if (stamp <= samples_.front().stamp)
    return beyond(samples_.front(), samples_[std::min<std::size_t>(1, samples_.size() - 1)]);
  if (stamp >= samples_.back().stamp)
    return beyond(samples_.back(), samples_[samples_.size() >= 2 ? samples_.size() - 2 : 0]);
  const auto upper = std::upper_bound(samples_.begin(), samples_.end(), stamp,
                                      [](double t, const Sample& sample) { return t < sample.stamp; });
  const Sample& a = *(upper - 1);
  const Sample& b = *upper;
  const double fraction = (stamp - a.stamp) / (b.stamp - a.stamp);  // a.stamp < stamp < b.stamp
  if (options_.use_orientation) return a.value + fraction * normalizeAngle(b.value - a.value);
  return a.value + fraction * (b.value - a.value);
}

bool GyroBuffer::rotation(double from, double to, double* angle) const {
  if (samples_.empty() || !std::isfinite(from) || !std::isfinite(to) || to < from) return false;
  if (from < samples_.front().stamp - options_.max_gap || to > samples_.back().stamp + options_.max_gap) {
    return false;
  }
  // Every instant of the interval must lie between two samples at most max_gap apart (or within max_gap
  // of the end sample beyond them).
  const auto after_from = std::upper_bound(samples_.begin(), samples_.end(), from,
                                           [](double t, const Sample& sample) { return t < sample.stamp; });
  for (auto it = after_from == samples_.begin() ? after_from : after_from - 1;
       it + 1 != samples_.end() && it->stamp < to; ++it) {
    if ((it + 1)->stamp - it->stamp > options_.max_gap) return false;
  }
  // Along the piecewise-linear signal from knot to knot: `from`, every sample between, `to`.
  double sum = 0.0;
  Sample previous{from, valueAt(from)};
  const auto add = [&](const Sample& knot) {
    sum += options_.use_orientation ? normalizeAngle(knot.value - previous.value)
                                    : 0.5 * (knot.value + previous.value) * (knot.stamp - previous.stamp);
    previous = knot;
  };
  for (auto it = after_from; it != samples_.end() && it->stamp < to; ++it) add(*it);
  add(Sample{to, valueAt(to)});
  *angle = sum;
  return true;
}

}  // namespace hglasm
