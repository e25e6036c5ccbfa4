// The motion of the base between two scans, predicted before the scan is matched (as Cartographer's
// PoseExtrapolator): by wheel odometry when it covers both stamps and moves plausibly, else at the
// velocity of the recent estimates; and that velocity, which also de-skews the scans.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <string>

#include "hglasm_odometry/core/motion_model.h"
#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

enum class PredictionSource { kOdometry, kConstantVelocity, kNone };
const char* toString(PredictionSource source);

/// The predicted motion of the base between two stamps, in its frame at the first, and its noise.
struct MotionPrediction {
  PredictionSource source = PredictionSource::kNone;
  Pose2D motion;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d nominal_covariance = Eigen::Matrix3d::Zero();  ///< wheels at unit noise scale
};

/// Not thread-safe per instance.
class PoseExtrapolator {
 public:
  /// `use_odometry`: predict from wheel odometry at all. `max_odometry_age`: seconds past the newest sample
  /// it may be extrapolated. Wheel motion faster than `max_speed` (m/s) or `max_turn_rate` (rad/s), plus a
  /// margin of 0.2 m / 0.2 rad for jitter, is a jump; the velocity is capped at both too.
  PoseExtrapolator(bool use_odometry, double max_odometry_age, double max_speed, double max_turn_rate);

  /// Wheel odometry: pose of the base in the wheel-odometry frame at `stamp`.
  void addOdometry(double stamp, const Pose2D& pose) { odometry_.add(stamp, pose); }
  /// Forgets the wheel odometry (it belongs to another timeline, e.g. time went back).
  void clearOdometry() { odometry_.clear(); }

  /// The motion of the base from `from` to `to`, with `noise`'s covariance. Sets *warning when the wheels
  /// jumped (the velocity predicts instead).
  MotionPrediction predict(double from, double to, const MotionNoiseModel& noise, std::string* warning) const;

  /// A new estimate of the base pose. The velocity becomes the motion over the last kVelocityBaseline
  /// seconds or more; returns that baseline, or 0 if there is none yet (then the velocity is kept, and
  /// forgotten once the newest older pose is kMaxVelocityAge old).
  double addPose(double stamp, const Pose2D& pose);

  bool velocityKnown() const { return velocity_known_; }
  /// vx, vy, wz of the base in its own frame.
  const Eigen::Vector3d& velocity() const { return velocity_; }

  /// Forgets the poses and the velocity; the wheel odometry is kept.
  void reset();

  /// Some logs hold bursts of scans ~1 ms apart whose stamps do not match their motion: a velocity over a
  /// shorter baseline would explode.
  static constexpr double kVelocityBaseline = 0.1;  // seconds
  static constexpr double kMaxVelocityAge = 2.0;    // seconds: older motion says nothing about the speed now

 private:
  bool use_odometry_;
  double max_odometry_age_;
  double max_speed_;
  double max_turn_rate_;
  OdometryBuffer odometry_;
  std::deque<StampedPose> poses_;  // recent estimates, for the velocity
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();
  bool velocity_known_ = false;
};

}  // namespace hglasm
