// Covariance algebra of planar poses: validity, clamping, frame changes, inverses and the normal density,
// each against a value worked out by hand.
#include "hglasm_odometry/core/covariance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test_util.h"

namespace {

using hglasm::Pose2D;
using hglasm_test::kPi;

TEST(Covariance, ValidPoseCovarianceIsFiniteSymmetricAndPositiveSemiDefinite) {
  EXPECT_TRUE(hglasm::isValidPoseCovariance(Eigen::Matrix3d::Zero()));
  EXPECT_TRUE(hglasm::isValidPoseCovariance(Eigen::Vector3d(0.1, 0.2, 0.01).asDiagonal()));
  Eigen::Matrix3d asymmetric = Eigen::Matrix3d::Identity();
  asymmetric(0, 1) = 0.1;
  EXPECT_FALSE(hglasm::isValidPoseCovariance(asymmetric));
  EXPECT_FALSE(hglasm::isValidPoseCovariance(Eigen::Vector3d(0.1, -0.2, 0.01).asDiagonal()));
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(2, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(hglasm::isValidPoseCovariance(nan));
}

TEST(Covariance, SymmetricClampedAveragesTheTransposeAndBoundsEveryEntry) {
  Eigen::Matrix3d m;
  m << 1.0, 2.0, 0.0, 4.0, 1e9, 0.0, 0.0, 0.0, -1e9;
  const Eigen::Matrix3d clamped = hglasm::symmetricClamped(m);
  EXPECT_EQ(clamped(0, 1), 3.0);
  EXPECT_EQ(clamped(1, 0), 3.0);
  EXPECT_EQ(clamped(1, 1), hglasm::kUnknownVariance);
  EXPECT_EQ(clamped(2, 2), -hglasm::kUnknownVariance);
}

TEST(Covariance, ComposeClampedMovesTheFirstPosesHeadingUncertaintyOntoTheLeverArm) {
  // A pose known but for its heading (0.01 rad^2), then 2 m straight ahead: the end is 2 m * 0.1 rad
  // uncertain sideways (y), i.e. 0.04 m^2, correlated with the heading by 2 * 0.01.
  const Eigen::Matrix3d a = Eigen::Vector3d(0.0, 0.0, 0.01).asDiagonal();
  const Eigen::Matrix3d composed =
      hglasm::composeClamped(Pose2D(), a, Pose2D(2.0, 0.0, 0.0), Eigen::Matrix3d::Zero());
  EXPECT_NEAR(composed(0, 0), 0.0, 1e-15);
  EXPECT_NEAR(composed(1, 1), 0.04, 1e-15);
  EXPECT_NEAR(composed(1, 2), 0.02, 1e-15);
  EXPECT_NEAR(composed(2, 2), 0.01, 1e-15);
}

TEST(Covariance, RotateCovarianceTurnsTheTranslationBlockOnly) {
  const Eigen::Matrix3d c = Eigen::Vector3d(1.0, 4.0, 0.5).asDiagonal();
  const Eigen::Matrix3d turned = hglasm::rotateCovariance(Pose2D(3.0, -1.0, kPi / 2), c);
  EXPECT_NEAR(turned(0, 0), 4.0, 1e-12);
  EXPECT_NEAR(turned(1, 1), 1.0, 1e-12);
  EXPECT_NEAR(turned(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(turned(2, 2), 0.5, 1e-12);
}

TEST(Covariance, InformationOfInvertsAndCovarianceOfInformationLeavesUnseenDirectionsUnknown) {
  const Eigen::Matrix3d c = Eigen::Vector3d(0.25, 4.0, 0.01).asDiagonal();
  EXPECT_TRUE(hglasm::informationOf(c).isApprox(
      Eigen::Vector3d(4.0, 0.25, 100.0).asDiagonal().toDenseMatrix(), 1e-9));
  // A corridor along x: the information says nothing about x.
  const Eigen::Matrix3d corridor = Eigen::Vector3d(0.0, 100.0, 400.0).asDiagonal();
  const Eigen::Matrix3d covariance = hglasm::covarianceOfInformation(corridor);
  EXPECT_NEAR(covariance(0, 0), hglasm::kUnknownVariance, 1e-6);
  EXPECT_NEAR(covariance(1, 1), 0.01, 1e-12);
  EXPECT_NEAR(covariance(2, 2), 0.0025, 1e-12);
}

TEST(Covariance, PoseDifferenceWrapsTheAngle) {
  const Eigen::Vector3d d = hglasm::poseDifference(Pose2D(1.0, 2.0, 3.0), Pose2D(0.5, 3.0, -3.0));
  EXPECT_NEAR(d.x(), 0.5, 1e-15);
  EXPECT_NEAR(d.y(), -1.0, 1e-15);
  EXPECT_NEAR(d.z(), 6.0 - 2.0 * kPi, 1e-12);
}

TEST(Covariance, LogNormalDensityIsTheGaussiansLogarithm) {
  const Eigen::Matrix3d c = Eigen::Vector3d(0.5, 2.0, 0.1).asDiagonal();
  const Eigen::Vector3d offset(0.3, -1.0, 0.2);
  double expected = 0.0;
  for (int i = 0; i < 3; ++i) {
    expected += -0.5 * offset[i] * offset[i] / c(i, i) - 0.5 * std::log(2.0 * kPi * c(i, i));
  }
  EXPECT_NEAR(hglasm::logNormalDensity(offset, hglasm::informationOf(c), c), expected, 1e-9);
  EXPECT_NEAR(hglasm::logDet2Pi(c), std::log(std::pow(2.0 * kPi, 3) * 0.5 * 2.0 * 0.1), 1e-12);
  EXPECT_EQ(hglasm::logDet2Pi(Eigen::Matrix3d::Zero()), std::log(1e-300)) << "floored, finite";
}

TEST(Covariance, JacobianOfMatchesTheAnalyticJacobianOfAComposition) {
  // f(x) = x * b: d f / d x is the adjoint-like matrix [I, R(theta) J b; 0 1] written out.
  const Pose2D b(2.0, 1.0, 0.3), x(0.5, -0.5, 0.7);
  const Eigen::Matrix3d jacobian = hglasm::jacobianOf([&](const Pose2D& p) { return p * b; }, x);
  const double c = std::cos(x.theta), s = std::sin(x.theta);
  Eigen::Matrix3d expected;
  expected << 1.0, 0.0, -s * b.x - c * b.y, 0.0, 1.0, c * b.x - s * b.y, 0.0, 0.0, 1.0;
  EXPECT_TRUE(jacobian.isApprox(expected, 1e-6)) << jacobian << "\nvs\n" << expected;
}

}  // namespace
