// What a scan match knows about the pose, direction by direction: the eigen-directions of its information
// (x, y, theta of the pose), so that each can be weighed by how far the scan is to be believed there.
#pragma once

#include <Eigen/Core>
#include <array>

namespace hglasm {

/// A heading error of 1 rad counts as this many metres when directions mixing translation and rotation are
/// compared (MbICP's metric length): without a length, "weakest direction" would depend on the units.
constexpr double kDirectionLength = 3.0;

/// Variance scales of the scan's information along its eigen-directions, weakest first: the information in
/// direction j is divided by scale[j]. (1, 1, 1): as the match states it.
using ScanNoiseScale = Eigen::Vector3d;

/// The eigen-decomposition of an information matrix in (x, y, kDirectionLength * theta).
struct InformationDirections {
  Eigen::Matrix3d vectors = Eigen::Matrix3d::Identity();  ///< unit columns, weakest first
  Eigen::Vector3d values = Eigen::Vector3d::Zero();       ///< ascending, >= 0

  /// Smallest / largest eigenvalue: 0 for a corridor's axis, 1 for a scan that constrains all equally.
  double degeneracy() const;
  /// The weakest direction as a pose change (x, y, theta), unit length in the scaled metric.
  Eigen::Vector3d weakestDirection() const;
};

/// Directions of `information` (of x, y, theta); all zero values for a non-finite matrix.
InformationDirections informationDirections(const Eigen::Matrix3d& information);

/// The matrix K with K * information = the information with direction j's share divided by scale[j]
/// (K commutes with it in the scaled metric, so a gradient b becomes K * b with the same minimum).
Eigen::Matrix3d scaledInformationMap(const InformationDirections& directions, const ScanNoiseScale& scale);

/// The covariance that direction j alone contributes (pseudo-inverse share, x, y, theta), its variance
/// capped at `max_variance` in the scaled metric: sum over j is the covariance of the information.
std::array<Eigen::Matrix3d, 3> covarianceByDirection(const InformationDirections& directions,
                                                     double max_variance);

}  // namespace hglasm
