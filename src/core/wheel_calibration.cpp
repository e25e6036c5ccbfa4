#include "hglasm_odometry/core/wheel_calibration.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace hglasm {
namespace {

constexpr double kOutlierSigmas = 4.0;

double square(double value) { return value * value; }

/// The prior information of an error whose standard deviation is `sigma` (0: known to be none).
double priorInformation(double sigma) { return 1.0 / square(std::max(sigma, 1e-9)); }

}  // namespace

WheelCalibration::WheelCalibration(const WheelCalibrationOptions& options) : options_(options) { reset(); }

void WheelCalibration::reset() {
  heading_.setZero();
  heading_vector_.setZero();
  heading_information_ =
      Eigen::Vector2d(priorInformation(options_.turn_scale), priorInformation(options_.heading_per_metre))
          .asDiagonal();
  distance_ = distance_vector_ = 0.0;
  distance_information_ = priorInformation(options_.distance_scale);
  offset_.setZero();
  offset_vector_.setZero();
  offset_information_ = Eigen::Matrix2d::Identity() * priorInformation(options_.laser_offset);
}

Pose2D WheelCalibration::correct(const Pose2D& wheel_motion) const {
  if (!wheel_motion.isFinite()) return wheel_motion;
  const double distance = wheel_motion.translationNorm();
  const double heading_error = heading_[0] * wheel_motion.theta + heading_[1] * distance;
  // Along an arc the chord turns by half the rotation: with the rotation corrected, so is the chord.
  const double c = std::cos(0.5 * heading_error), s = std::sin(0.5 * heading_error);
  const double scale = 1.0 + distance_;
  return Pose2D(scale * (c * wheel_motion.x - s * wheel_motion.y),
                scale * (s * wheel_motion.x + c * wheel_motion.y), wheel_motion.theta + heading_error);
}

void WheelCalibration::learn(const Pose2D& wheel_motion, const Pose2D& scan_motion, double heading_variance,
                             double distance_variance) {
  if (!options_.learn || !wheel_motion.isFinite() || !scan_motion.isFinite()) return;
  // Forgetting pulls the information back towards the prior's, so the estimates follow slow changes.
  const double forget = std::exp2(-1.0 / std::max(1.0, options_.half_life));
  const Eigen::Matrix2d prior =
      Eigen::Vector2d(priorInformation(options_.turn_scale), priorInformation(options_.heading_per_metre))
          .asDiagonal();
  const double distance = wheel_motion.translationNorm();
  const Eigen::Vector2d regressors(wheel_motion.theta, distance);
  const double heading_residual = normalizeAngle(scan_motion.theta - wheel_motion.theta);
  if (heading_variance > 0.0 &&
      square(heading_residual - regressors.dot(heading_)) <= square(kOutlierSigmas) * heading_variance) {
    heading_information_ = forget * heading_information_ + (1.0 - forget) * prior +
                           regressors * regressors.transpose() / heading_variance;
    heading_vector_ = forget * heading_vector_ + regressors * heading_residual / heading_variance;
    heading_ = heading_information_.lu().solve(heading_vector_);
  }
  if (options_.distance_scale > 0.0 && distance > 1e-3 && distance_variance > 0.0) {
    // The scans' distance along the wheels' direction of travel.
    const double along = (scan_motion.x * wheel_motion.x + scan_motion.y * wheel_motion.y) / distance;
    const double residual = along - distance;
    if (square(residual - distance_ * distance) <= square(kOutlierSigmas) * distance_variance) {
      const double prior_distance = priorInformation(options_.distance_scale);
      distance_information_ = forget * distance_information_ + (1.0 - forget) * prior_distance +
                              distance * distance / distance_variance;
      distance_vector_ = forget * distance_vector_ + distance * residual / distance_variance;
      distance_ = distance_vector_ / distance_information_;
    }
  }
}

void WheelCalibration::learnLaserOffset(const Pose2D& wheel_motion, const Pose2D& laser_motion,
                                        const Pose2D& stated_mount, const Eigen::Matrix2d& covariance) {
  if (!options_.learn || !(options_.laser_offset > 0.0) || !wheel_motion.isFinite() ||
      !laser_motion.isFinite() || !stated_mount.isFinite() || !covariance.allFinite()) {
    return;
  }
  const Eigen::Matrix2d information = covariance.inverse();
  if (!information.allFinite() || !(information.determinant() > 0.0)) return;
  // The base motion the laser's implies with the stated mount s: R(phi) t_laser + (I - R(turn)) s. The
  // laser truly at s + d makes it the wheels' + (R(turn) - I) d.
  const Pose2D scan_base = stated_mount * laser_motion * stated_mount.inverse();
  const Pose2D wheels = correct(wheel_motion);
  const Eigen::Vector2d residual(scan_base.x - wheels.x, scan_base.y - wheels.y);
  // The turn as the laser saw it: wheels that slip in turns (or an IMU's rotation) miscount it.
  const double c = std::cos(laser_motion.theta), s = std::sin(laser_motion.theta);
  Eigen::Matrix2d regressor;
  regressor << c - 1.0, -s, s, c - 1.0;
  const Eigen::Vector2d innovation = residual - regressor * offset_;
  // The innovation's covariance includes what is not yet known of the offset.
  const Eigen::Matrix2d innovation_covariance =
      covariance + regressor * offset_information_.inverse() * regressor.transpose();
  if (innovation.dot(innovation_covariance.inverse() * innovation) > square(kOutlierSigmas)) return;
  const double forget = std::exp2(-1.0 / std::max(1.0, options_.half_life));
  offset_information_ =
      forget * offset_information_ +
      (1.0 - forget) * Eigen::Matrix2d::Identity() * priorInformation(options_.laser_offset) +
      regressor.transpose() * information * regressor;
  offset_vector_ = forget * offset_vector_ + regressor.transpose() * information * residual;
  offset_ = offset_information_.lu().solve(offset_vector_);
}

}  // namespace hglasm
