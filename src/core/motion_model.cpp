#include "hglasm_odometry/core/motion_model.h"

#include <algorithm>
#include <cmath>

namespace hglasm {
namespace {

double square(double value) { return value * value; }

}  // namespace

MotionNoiseModel::MotionNoiseModel(const MotionNoiseOptions& options) : options_(options) {}

Eigen::Matrix3d MotionNoiseModel::nominalOdometryCovariance(const Pose2D& increment, double dt) const {
  const double distance = increment.translationNorm();
  const double turn = std::abs(increment.theta);
  const double elapsed = std::isfinite(dt) ? std::max(0.0, dt) : 0.0;
  const double var_xy = square(options_.xy_per_metre) * distance + square(options_.xy_per_radian) * turn +
                        square(options_.xy_per_second) * elapsed;
  const double var_theta = square(options_.theta_per_metre) * distance +
                           square(options_.theta_per_radian) * turn +
                           square(options_.theta_per_second) * elapsed;
  // Never exactly zero: a covariance must stay invertible.
  return Eigen::Vector3d(std::max(var_xy, 1e-12), std::max(var_xy, 1e-12), std::max(var_theta, 1e-12))
      .asDiagonal();
}

Eigen::Matrix3d MotionNoiseModel::odometryCovariance(const Pose2D& increment, double dt) const {
  Eigen::Matrix3d covariance = nominalOdometryCovariance(increment, dt);
  covariance.topLeftCorner<2, 2>() *= scale_.xy;
  covariance(2, 2) *= scale_.theta;
  return covariance + systematicCovariance(increment);
}

Eigen::Matrix3d MotionNoiseModel::systematicCovariance(const Pose2D& increment) const {
  const double xy = square(options_.systematic * increment.translationNorm());
  const double theta = square(options_.systematic * increment.theta);
  return Eigen::Vector3d(xy, xy, theta).asDiagonal();
}

Eigen::Matrix3d MotionNoiseModel::constantVelocityCovariance(double dt) const {
  const double elapsed = std::isfinite(dt) ? std::max(0.0, dt) : 0.0;
  const double step_sq = elapsed * elapsed;
  const double var_xy = std::max(square(options_.constant_velocity_velocity_xy * elapsed) +
                                     square(0.5 * options_.constant_velocity_xy * step_sq),
                                 1e-12);
  const double var_theta = std::max(square(options_.constant_velocity_velocity_theta * elapsed) +
                                        square(0.5 * options_.constant_velocity_theta * step_sq),
                                    1e-12);
  return Eigen::Vector3d(var_xy, var_xy, var_theta).asDiagonal();
}

}  // namespace hglasm
