// A short history of wheel-odometry poses, interpolated to scan stamps.
#pragma once

#include <cstddef>
#include <deque>
#include <limits>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

class OdometryBuffer {
 public:
  explicit OdometryBuffer(double max_age = 30.0) : max_age_(max_age) {}

  /// Adds a sample. Out-of-order samples are inserted in place; non-finite ones are rejected (false).
  /// Samples older than max_age behind the newest are dropped, except those within `margin` of the stamp
  /// keepAround() names (and the two that bracket that span).
  bool add(double stamp, const Pose2D& pose);

  /// The pose at `stamp` stays interpolable whatever comes after (the start of the next prediction: a
  /// pause of any length while the wheels keep publishing), from samples within `margin` seconds of it.
  void keepAround(double stamp, double margin);

  /// Pose at `stamp`, interpolated between the two samples around it. After the newest sample it
  /// extrapolates with the velocity over the last 0.05-1 s of samples (holds the newest sample if there is
  /// no such baseline), before the oldest it holds the oldest; at most `max_extrapolation` seconds, else
  /// false. `outside` (optional) receives the seconds from `stamp` to the nearest sample when it lies
  /// outside the samples (what they do not cover), else 0.
  bool poseAt(double stamp, double max_extrapolation, Pose2D* pose, double* outside = nullptr) const;

  /// The longest time between consecutive samples over [from, to] (the samples around either end
  /// included): how finely the buffer knows the motion there. Infinity where it does not cover the span.
  double largestGap(double from, double to) const;

  /// The fastest turn between consecutive samples over [from, to] (rad/s; the samples around either end
  /// included; infinity for a turn between two samples of one stamp or where it does not cover the span).
  double largestTurnRate(double from, double to) const;

  double newestStamp() const;
  bool empty() const { return samples_.empty(); }
  std::size_t size() const { return samples_.size(); }
  void clear() { samples_.clear(); }

 private:
  struct Sample {
    double stamp;
    Pose2D pose;
  };
  static constexpr double kMinVelocityBaseline = 0.05;  // seconds
  static constexpr double kMaxVelocityBaseline = 1.0;   // seconds
  void prune();
  double max_age_;                                               // seconds kept behind the newest sample
  double keep_from_ = -std::numeric_limits<double>::infinity();  // keepAround(): its span
  double keep_to_ = -std::numeric_limits<double>::infinity();
  std::deque<Sample> samples_;
};

}  // namespace hglasm
