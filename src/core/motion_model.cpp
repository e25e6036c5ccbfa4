#include "hglasm_odometry/core/motion_model.h"

#include <algorithm>
#include <cmath>

namespace hglasm {
namespace {

double square(double value) { return value * value; }

// A sample may raise the sums by at most this many times what the current model expects, so one bad
// match (a door swinging) does not teach the model that the wheels are bad.
constexpr double kMaxNormalisedSample = 16.0;
constexpr double kPriorSamples = 10.0;

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
  return covariance;
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

void MotionNoiseModel::resetLearning() {
  scale_ = MotionNoiseScale();
  xy_excess_ = xy_nominal_ = theta_excess_ = theta_nominal_ = 0.0;
}

void MotionNoiseModel::learn(const Eigen::Vector3d& innovation, const Eigen::Vector3d& explained,
                             const Eigen::Vector3d& nominal) {
  if (!options_.learn || !innovation.allFinite() || !explained.allFinite() || !nominal.allFinite()) return;
  const double forget = std::exp2(-1.0 / std::max(1.0, options_.learn_half_life));
  const auto update = [&](double innovation_sq, double explained_var, double nominal_var, double* excess,
                          double* nominal_sum, double* scale) {
    if (!(nominal_var > 0.0)) return;
    if (*nominal_sum == 0.0) {
      // Start from the configured model as if it had been seen kPriorSamples times: the first few matches
      // alone would set the scale anywhere.
      *nominal_sum = kPriorSamples * nominal_var;
      *excess = *scale * *nominal_sum;
    }
    const double expected = explained_var + *scale * nominal_var;
    const double sample = std::min(innovation_sq, kMaxNormalisedSample * expected);
    *excess = forget * *excess + (sample - explained_var);
    *nominal_sum = forget * *nominal_sum + nominal_var;
    *scale = std::clamp(*excess / *nominal_sum, options_.min_scale, options_.max_scale);
  };
  update(innovation.head<2>().squaredNorm(), explained.x() + explained.y(), nominal.x() + nominal.y(),
         &xy_excess_, &xy_nominal_, &scale_.xy);
  update(square(innovation.z()), explained.z(), nominal.z(), &theta_excess_, &theta_nominal_, &scale_.theta);
}

}  // namespace hglasm
