// The scan's information direction by direction: eigen-directions in a common metric, scaling one
// direction at a time, and the covariance each direction contributes.
#include "hglasm_odometry/core/scan_information.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

namespace {

using hglasm::InformationDirections;
using hglasm::kDirectionLength;
using hglasm::ScanNoiseScale;

/// A corridor along x seen from its middle: nothing along it, the walls across it and the heading.
Eigen::Matrix3d corridorInformation(double along) {
  return Eigen::Vector3d(along, 400.0, 900.0).asDiagonal();
}

TEST(ScanInformation, TheWeakestDirectionIsTheCorridorsAxis) {
  const InformationDirections directions = hglasm::informationDirections(corridorInformation(0.0));
  EXPECT_NEAR(std::abs(directions.weakestDirection().x()), 1.0, 1e-12);
  EXPECT_NEAR(directions.degeneracy(), 0.0, 1e-12);
  // Heading in the metric's units: 900 per rad^2 is 900 / L^2 per (L rad)^2.
  EXPECT_NEAR(directions.values[1], 900.0 / (kDirectionLength * kDirectionLength), 1e-9);
  EXPECT_NEAR(directions.values[2], 400.0, 1e-9);
  // Equal information in every direction of the metric is not degenerate at all.
  const Eigen::Matrix3d round = Eigen::Vector3d(1.0, 1.0, kDirectionLength * kDirectionLength).asDiagonal();
  EXPECT_NEAR(hglasm::informationDirections(round).degeneracy(), 1.0, 1e-12);
  // Garbage in: no direction.
  Eigen::Matrix3d broken = corridorInformation(1.0);
  broken(0, 1) = std::nan("");
  EXPECT_EQ(hglasm::informationDirections(broken).degeneracy(), 0.0);
}

TEST(ScanInformation, AScaleDividesItsOwnDirectionOnly) {
  // A rotated corridor (axis at 30 degrees, heading coupled to the cross-track offset) so that the map
  // has to work in the eigenbasis, not on the diagonal.
  Eigen::Matrix3d information;
  information << 300.0, -150.0, 40.0, -150.0, 120.0, -25.0, 40.0, -25.0, 700.0;
  const InformationDirections directions = hglasm::informationDirections(information);
  const Eigen::Matrix3d unchanged = hglasm::scaledInformationMap(directions, ScanNoiseScale::Ones());
  EXPECT_TRUE(unchanged.isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  const ScanNoiseScale scale(10.0, 1.0, 0.5);
  const Eigen::Matrix3d scaled = hglasm::scaledInformationMap(directions, scale) * information;
  EXPECT_TRUE(scaled.isApprox(scaled.transpose(), 1e-9)) << "still an information matrix:\n" << scaled;
  const InformationDirections after = hglasm::informationDirections(scaled);
  for (int j = 0; j < 3; ++j) {
    // The same directions (up to sign); each value divided by its own scale. Scaling by (10, 1, 0.5)
    // keeps the order here.
    EXPECT_NEAR(std::abs(after.vectors.col(j).dot(directions.vectors.col(j))), 1.0, 1e-9) << j;
    EXPECT_NEAR(after.values[j], directions.values[j] / scale[j], 1e-9 * directions.values[2]) << j;
  }
  // A gradient mapped the same way keeps the scan's own minimum: K I x = K b solves I x = b.
  const Eigen::Vector3d gradient(0.3, -0.1, 0.05);
  const Eigen::Matrix3d map = hglasm::scaledInformationMap(directions, scale);
  EXPECT_TRUE(scaled.lu().solve(map * gradient).isApprox(information.lu().solve(gradient), 1e-9));
}

TEST(ScanInformation, TheDirectionsCovariancesSumToTheInverse) {
  Eigen::Matrix3d information;
  information << 300.0, -150.0, 40.0, -150.0, 120.0, -25.0, 40.0, -25.0, 700.0;
  const auto parts = hglasm::covarianceByDirection(hglasm::informationDirections(information), 1e4);
  const Eigen::Matrix3d sum = parts[0] + parts[1] + parts[2];
  EXPECT_TRUE(sum.isApprox(information.inverse(), 1e-9)) << sum << "\n\n" << information.inverse();
  // A direction the scan says nothing about gets the capped variance, not infinity.
  const auto corridor =
      hglasm::covarianceByDirection(hglasm::informationDirections(corridorInformation(0.0)), 1e4);
  EXPECT_NEAR(corridor[0](0, 0), 1e4, 1e-6);
  EXPECT_TRUE(corridor[0].allFinite());
}

}  // namespace
