#include "hglasm_odometry/core/scan_information.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace hglasm {
namespace {

/// (x, y, theta) -> (x, y, L theta).
Eigen::Matrix3d metricScale() { return Eigen::Vector3d(1.0, 1.0, kDirectionLength).asDiagonal(); }

}  // namespace

double InformationDirections::degeneracy() const {
  return values[2] > 0.0 ? std::max(0.0, values[0]) / values[2] : 0.0;
}

Eigen::Vector3d InformationDirections::weakestDirection() const {
  Eigen::Vector3d direction = vectors.col(0);
  direction.z() /= kDirectionLength;
  return direction;
}

InformationDirections informationDirections(const Eigen::Matrix3d& information) {
  InformationDirections directions;
  if (!information.allFinite()) return directions;
  // Information of (x, y, L theta) = T^-1 I T^-1 with T = diag(1, 1, L).
  const Eigen::Matrix3d inverse_scale = metricScale().inverse();
  const Eigen::Matrix3d scaled =
      inverse_scale * (0.5 * (information + information.transpose())) * inverse_scale;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scaled);
  if (solver.info() != Eigen::Success) return directions;
  directions.vectors = solver.eigenvectors();
  directions.values = solver.eigenvalues().cwiseMax(0.0);
  return directions;
}

Eigen::Matrix3d scaledInformationMap(const InformationDirections& directions, const ScanNoiseScale& scale) {
  // In the scaled metric the map is V diag(1 / scale) V^T; back in (x, y, theta) it is T (.) T^-1.
  const Eigen::Vector3d inverse = scale.cwiseMax(1e-12).cwiseInverse();
  const Eigen::Matrix3d scaled = directions.vectors * inverse.asDiagonal() * directions.vectors.transpose();
  return metricScale() * scaled * metricScale().inverse();
}

std::array<Eigen::Matrix3d, 3> covarianceByDirection(const InformationDirections& directions,
                                                     double max_variance) {
  std::array<Eigen::Matrix3d, 3> parts;
  const Eigen::Matrix3d inverse_scale = metricScale().inverse();
  for (int j = 0; j < 3; ++j) {
    const double value = directions.values[j];
    const double variance = value > 1.0 / max_variance ? 1.0 / value : max_variance;
    const Eigen::Vector3d v = inverse_scale * directions.vectors.col(j);
    parts[j] = variance * v * v.transpose();
  }
  return parts;
}

}  // namespace hglasm
