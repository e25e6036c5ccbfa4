// A short history of wheel-odometry poses, interpolated to scan stamps.
#pragma once

#include <cstddef>
#include <deque>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

class OdometryBuffer {
 public:
  explicit OdometryBuffer(double max_age = 30.0) : max_age_(max_age) {}

  /// Adds a sample. Out-of-order samples are inserted in place; non-finite ones are rejected (false).
  bool add(double stamp, const Pose2D& pose);

  /// Pose at `stamp`, interpolated between the two samples around it. After the newest sample it
  /// extrapolates with the velocity over the last 0.05-1 s of samples (holds the newest sample if there is
  /// no such baseline), before the oldest it holds the oldest; at most `max_extrapolation` seconds, else
  /// false.
  bool poseAt(double stamp, double max_extrapolation, Pose2D* pose) const;

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
  double max_age_;                                      // seconds kept behind the newest sample
  std::deque<Sample> samples_;
};

}  // namespace hglasm
