#include "hglasm_odometry/core/covariance.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace hglasm {

bool isValidPoseCovariance(const Eigen::Matrix3d& covariance) {
  if (!covariance.allFinite()) return false;
  const double scale = 1.0 + covariance.cwiseAbs().maxCoeff();
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(0.5 * (covariance + covariance.transpose()),
                                                              Eigen::EigenvaluesOnly);
  return solver.eigenvalues().minCoeff() >= -1e-12 * scale;
}

Eigen::Matrix3d symmetricClamped(const Eigen::Matrix3d& covariance) {
  const Eigen::Matrix3d symmetric = 0.5 * (covariance + covariance.transpose());
  return symmetric.cwiseMin(kUnknownVariance).cwiseMax(-kUnknownVariance);
}

Eigen::Matrix3d composeClamped(const Pose2D& a, const Eigen::Matrix3d& cov_a, const Pose2D& b,
                               const Eigen::Matrix3d& cov_b) {
  return symmetricClamped(composeCovariance(a, cov_a, b, cov_b));
}

Eigen::Matrix3d rotateCovariance(const Pose2D& frame_change, const Eigen::Matrix3d& covariance) {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  const double c = std::cos(frame_change.theta), s = std::sin(frame_change.theta);
  rotation.topLeftCorner<2, 2>() << c, -s, s, c;
  return symmetricClamped(rotation * covariance * rotation.transpose());
}

Eigen::Matrix3d informationOf(const Eigen::Matrix3d& covariance) {
  return (covariance + Eigen::Matrix3d::Identity() * 1e-12).inverse();
}

Eigen::Matrix3d covarianceOfInformation(const Eigen::Matrix3d& information) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(information);
  const Eigen::Vector3d eigenvalues = solver.eigenvalues();
  Eigen::Vector3d variances;
  for (int i = 0; i < 3; ++i) {
    variances[i] = eigenvalues[i] > 1e-6 * std::max(eigenvalues.maxCoeff(), 1e-12) ? 1.0 / eigenvalues[i]
                                                                                   : kUnknownVariance;
  }
  return solver.eigenvectors() * variances.asDiagonal() * solver.eigenvectors().transpose();
}

Eigen::Vector3d poseDifference(const Pose2D& a, const Pose2D& b) {
  return Eigen::Vector3d(a.x - b.x, a.y - b.y, normalizeAngle(a.theta - b.theta));
}

double logDet2Pi(const Eigen::Matrix3d& covariance) {
  return std::log(std::max((2.0 * M_PI * covariance).determinant(), 1e-300));
}

double logNormalDensity(const Eigen::Vector3d& offset, const Eigen::Matrix3d& information,
                        const Eigen::Matrix3d& covariance) {
  return -0.5 * offset.dot(information * offset) - 0.5 * logDet2Pi(covariance);
}

}  // namespace hglasm
