// Covariance algebra of planar poses (x, y, theta), beside pose2d.h: kept finite, changed of frame,
// inverted, and the Gaussian's log density.
#pragma once

#include <Eigen/Core>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

/// The variance published for what is not known (a covariance must stay finite).
constexpr double kUnknownVariance = 1e4;

/// A pose covariance (x, y, theta) a caller may hand in: finite, symmetric (to 1e-9 relative) and positive
/// semi-definite (to rounding).
bool isValidPoseCovariance(const Eigen::Matrix3d& covariance);

/// Symmetrised, every entry within +-kUnknownVariance.
Eigen::Matrix3d symmetricClamped(const Eigen::Matrix3d& covariance);

/// composeCovariance, kept finite (symmetricClamped).
Eigen::Matrix3d composeClamped(const Pose2D& a, const Eigen::Matrix3d& cov_a, const Pose2D& b,
                               const Eigen::Matrix3d& cov_b);

/// Covariance of a pose's coordinates after its frame is changed by the rigid motion `frame_change`.
Eigen::Matrix3d rotateCovariance(const Pose2D& frame_change, const Eigen::Matrix3d& covariance);

/// Inverse of a covariance that may be nearly singular in one direction (a prior's never is).
Eigen::Matrix3d informationOf(const Eigen::Matrix3d& covariance);

/// The covariance an information matrix states: the inverse of each eigenvalue, kUnknownVariance along
/// directions it holds (next to) nothing about.
Eigen::Matrix3d covarianceOfInformation(const Eigen::Matrix3d& information);

/// a - b per coordinate, the angle wrapped.
Eigen::Vector3d poseDifference(const Pose2D& a, const Pose2D& b);

/// log det(2 pi covariance), floored at log(1e-300): twice the log volume of a normal density.
double logDet2Pi(const Eigen::Matrix3d& covariance);

/// log of the normal density at `offset` from its mean, with `information` the inverse of `covariance`.
double logNormalDensity(const Eigen::Vector3d& offset, const Eigen::Matrix3d& information,
                        const Eigen::Matrix3d& covariance);

/// d f / d x at x (x, y, theta coordinates, angles wrapped), by central differences: for the few rigid-frame
/// changes per scan whose Jacobians are tedious to write out (a laser mount's lever arm).
template <typename Function>
Eigen::Matrix3d jacobianOf(const Function& f, const Pose2D& x) {
  constexpr double kStep = 1e-6;
  Eigen::Matrix3d jacobian;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    delta[k] = kStep;
    const Pose2D plus = f(Pose2D(x.x + delta.x(), x.y + delta.y(), x.theta + delta.z()));
    const Pose2D minus = f(Pose2D(x.x - delta.x(), x.y - delta.y(), x.theta - delta.z()));
    jacobian.col(k) << (plus.x - minus.x) / (2 * kStep), (plus.y - minus.y) / (2 * kStep),
        normalizeAngle(plus.theta - minus.theta) / (2 * kStep);
  }
  return jacobian;
}

}  // namespace hglasm
