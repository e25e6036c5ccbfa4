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
  /// Wheels also miscount systematically (a wheel radius, a wheel base off by a fraction): an error that
  /// grows with the distance and the turn themselves, not their square roots. It dominates a long step (the
  /// wheels across a pause of minutes) and is never learned away. Fraction of the distance and the turn.
  double systematic = 0.0;
  /// Without wheel odometry the motion is extrapolated at the velocity of the last scans' poses. The guess
  /// is off by the velocity's own error times the step plus half the acceleration times its square.
  double constant_velocity_xy = 1.0;              ///< m/s per s: acceleration (standard deviation)
  double constant_velocity_theta = 1.5;           ///< rad/s per s: angular acceleration
  double constant_velocity_velocity_xy = 0.2;     ///< m/s: error of the velocity measured from the scans
  double constant_velocity_velocity_theta = 0.3;  ///< rad/s: error of the turn rate measured from the scans
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, MotionNoiseOptions* options) {
  visitor.nonNegativeNumber("odometry/noise/xy_per_metre", &options->xy_per_metre);
  visitor.nonNegativeNumber("odometry/noise/xy_per_radian", &options->xy_per_radian);
  visitor.nonNegativeNumber("odometry/noise/xy_per_second", &options->xy_per_second);
  visitor.nonNegativeNumber("odometry/noise/theta_per_metre", &options->theta_per_metre);
  visitor.nonNegativeNumber("odometry/noise/theta_per_radian", &options->theta_per_radian);
  visitor.nonNegativeNumber("odometry/noise/theta_per_second", &options->theta_per_second);
  visitor.nonNegativeNumber("odometry/noise/systematic", &options->systematic);
  visitor.positiveNumber("constant_velocity/xy", &options->constant_velocity_xy);
  visitor.positiveNumber("constant_velocity/theta", &options->constant_velocity_theta);
  visitor.nonNegativeNumber("constant_velocity/velocity_xy", &options->constant_velocity_velocity_xy);
  visitor.nonNegativeNumber("constant_velocity/velocity_theta", &options->constant_velocity_velocity_theta);
}

/// What a predicted motion's noise is made of: the two variance scales of the wheels' model.
struct MotionNoiseScale {
  double xy = 1.0;
  double theta = 1.0;
};

/// Wheel-odometry noise model, its two variance scales set from outside (learned). Not thread-safe per
/// instance.
class MotionNoiseModel {
 public:
  explicit MotionNoiseModel(const MotionNoiseOptions& options = {});

  /// Covariance of a wheel-odometry increment (x, y, theta in the frame where it starts) over `dt` s.
  Eigen::Matrix3d odometryCovariance(const Pose2D& increment, double dt) const;
  /// The random-walk part at unit scale (the configured model, before learning).
  Eigen::Matrix3d nominalOdometryCovariance(const Pose2D& increment, double dt) const;
  /// The systematic part (options().systematic): not learned, part of every odometryCovariance().
  Eigen::Matrix3d systematicCovariance(const Pose2D& increment) const;
  /// Covariance of a constant-velocity extrapolation over `dt` seconds.
  Eigen::Matrix3d constantVelocityCovariance(double dt) const;

  /// The wheels' variance scales (learned: NoiseLearner); 1 is the configured model.
  void setScale(const MotionNoiseScale& scale) { scale_ = scale; }
  const MotionNoiseScale& scale() const { return scale_; }
  const MotionNoiseOptions& options() const { return options_; }

 private:
  MotionNoiseOptions options_;
  MotionNoiseScale scale_;
};

}  // namespace hglasm
