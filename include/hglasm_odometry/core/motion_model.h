// How far a predicted motion may be off: the noise of wheel odometry (learned online) and of a
// constant-velocity guess.
#pragma once

#include <Eigen/Core>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

struct MotionNoiseOptions {
  /// Wheel odometry drifts like a random walk: each variance grows linearly with the distance travelled,
  /// the angle turned and the time elapsed (a push or a vibration while standing). Each value is the
  /// standard deviation reached after one unit (1 m, 1 rad or 1 s) of that alone.
  double xy_per_metre = 0.05;       ///< m of translation noise after 1 m travelled
  double xy_per_radian = 0.02;      ///< m after 1 rad turned
  double xy_per_second = 0.002;     ///< m after 1 s
  double theta_per_metre = 0.02;    ///< rad of heading noise after 1 m travelled
  double theta_per_radian = 0.05;   ///< rad after 1 rad turned
  double theta_per_second = 0.002;  ///< rad after 1 s
  /// Without wheel odometry the motion is extrapolated at the velocity of the last scans' poses. The guess
  /// is off by the velocity's own error times the step plus half the acceleration times its square.
  double constant_velocity_xy = 1.0;              ///< m/s per s: acceleration (standard deviation)
  double constant_velocity_theta = 1.5;           ///< rad/s per s: angular acceleration
  double constant_velocity_velocity_xy = 0.2;     ///< m/s: error of the velocity measured from the scans
  double constant_velocity_velocity_theta = 0.3;  ///< rad/s: error of the turn rate measured from the scans
  /// Learn the wheels' noise online: scale the translation and the heading variances above by what the
  /// scan matches show about the wheel increments (method of moments, exponential forgetting), so that one
  /// configuration serves robots with good and with bad wheels.
  bool learn = true;
  double learn_half_life = 200.0;  ///< matched scans after which an old increment counts half
  double min_scale = 0.01;         ///< bounds of the learned variance scale
  double max_scale = 100.0;
};

/// What a predicted motion's noise is made of: the two variance scales of the wheels' model.
struct MotionNoiseScale {
  double xy = 1.0;
  double theta = 1.0;
};

/// Wheel-odometry noise model with learned scales. Not thread-safe per instance.
class MotionNoiseModel {
 public:
  explicit MotionNoiseModel(const MotionNoiseOptions& options = {});

  /// Covariance of a wheel-odometry increment (x, y, theta in the frame where it starts) over `dt` s.
  Eigen::Matrix3d odometryCovariance(const Pose2D& increment, double dt) const;
  /// The same at unit scale (the configured model, before learning).
  Eigen::Matrix3d nominalOdometryCovariance(const Pose2D& increment, double dt) const;
  /// Covariance of a constant-velocity extrapolation over `dt` seconds.
  Eigen::Matrix3d constantVelocityCovariance(double dt) const;

  /// One matched increment: `innovation` is (scan-only estimate - prediction), x and y in metres, theta in
  /// radians; `explained` the variance of that innovation not due to the wheels (the match's own, the
  /// previous estimate's); `nominal` the unit-scale wheel covariance of the increment (diagonal used).
  void learn(const Eigen::Vector3d& innovation, const Eigen::Vector3d& explained,
             const Eigen::Vector3d& nominal);

  const MotionNoiseScale& scale() const { return scale_; }
  void resetLearning();
  const MotionNoiseOptions& options() const { return options_; }

 private:
  MotionNoiseOptions options_;
  MotionNoiseScale scale_;
  // Exponentially forgotten sums of the method of moments: scale = sum(innovation^2 - explained) /
  // sum(nominal).
  double xy_excess_ = 0.0, xy_nominal_ = 0.0;
  double theta_excess_ = 0.0, theta_nominal_ = 0.0;
};

}  // namespace hglasm
