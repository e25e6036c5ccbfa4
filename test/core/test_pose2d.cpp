// SE(2) poses: normalisation (incl. the +-pi seam), compose, inverse, relative pose, interpolation, adjoint.
#include "hglasm_odometry/core/pose2d.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "test_util.h"

namespace {

using hglasm::Pose2D;
using hglasm_test::angleDiff;
using hglasm_test::kPi;

constexpr double kEps = 1e-12;

void expectPoseNear(const Pose2D& actual, const Pose2D& expected, double tolerance = 1e-12) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(angleDiff(actual.theta, expected.theta), 0.0, tolerance);
  EXPECT_GT(actual.theta, -kPi);  // always normalised into (-pi, pi]
  EXPECT_LE(actual.theta, kPi);
}

TEST(NormalizeAngle, KeepsAnglesInsideTheRange) {
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(1.0), 1.0);
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(-1.0), -1.0);
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(3.0), 3.0);
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(-3.0), -3.0);
}

TEST(NormalizeAngle, WrapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(-kPi), kPi);  // -pi is outside (-pi, pi]
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(3.0 * kPi), kPi);
  EXPECT_DOUBLE_EQ(hglasm::normalizeAngle(-3.0 * kPi), kPi);
  EXPECT_NEAR(hglasm::normalizeAngle(2.0 * kPi), 0.0, kEps);
  EXPECT_NEAR(hglasm::normalizeAngle(-2.0 * kPi), 0.0, kEps);
  EXPECT_NEAR(hglasm::normalizeAngle(kPi + 0.1), -kPi + 0.1, kEps);
  EXPECT_NEAR(hglasm::normalizeAngle(-kPi - 0.1), kPi - 0.1, kEps);
  EXPECT_NEAR(hglasm::normalizeAngle(7.0), 7.0 - 2.0 * kPi, kEps);
  EXPECT_NEAR(hglasm::normalizeAngle(-7.0), -7.0 + 2.0 * kPi, kEps);
  EXPECT_NEAR(hglasm::normalizeAngle(1000.0), std::atan2(std::sin(1000.0), std::cos(1000.0)), 1e-9);
  EXPECT_NEAR(hglasm::normalizeAngle(-1e6), std::atan2(std::sin(-1e6), std::cos(-1e6)), 1e-6);
}

TEST(NormalizeAngle, JustInsideTheSeamStaysPut) {
  const double just_above_minus_pi = std::nextafter(-kPi, 0.0);
  const double result = hglasm::normalizeAngle(just_above_minus_pi);
  EXPECT_GT(result, -kPi);
  EXPECT_LE(result, kPi);
  EXPECT_NEAR(angleDiff(result, just_above_minus_pi), 0.0, kEps);
}

TEST(NormalizeAngle, ResultAlwaysInRangeForManyAngles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-50.0, 50.0);
  for (int i = 0; i < 10000; ++i) {
    const double a = angle(rng);
    const double n = hglasm::normalizeAngle(a);
    ASSERT_GT(n, -kPi) << a;
    ASSERT_LE(n, kPi) << a;
    ASSERT_NEAR(std::sin(n), std::sin(a), 1e-9) << a;
    ASSERT_NEAR(std::cos(n), std::cos(a), 1e-9) << a;
  }
}

TEST(NormalizeAngle, NonFiniteReturnedUnchanged) {
  EXPECT_TRUE(std::isnan(hglasm::normalizeAngle(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_FALSE(std::isfinite(hglasm::normalizeAngle(std::numeric_limits<double>::infinity())));
}

TEST(Pose2D, ConstructorNormalisesTheta) {
  const Pose2D pose(1.0, 2.0, 3.0 * kPi / 2.0);
  EXPECT_DOUBLE_EQ(pose.x, 1.0);
  EXPECT_DOUBLE_EQ(pose.y, 2.0);
  EXPECT_NEAR(pose.theta, -kPi / 2.0, kEps);
  EXPECT_TRUE(pose.isFinite());
  EXPECT_FALSE(Pose2D(std::nan(""), 0.0, 0.0).isFinite());
  EXPECT_FALSE(Pose2D(0.0, 0.0, std::numeric_limits<double>::infinity()).isFinite());
  EXPECT_DOUBLE_EQ(Pose2D(3.0, 4.0, 0.0).translationNorm(), 5.0);
}

TEST(Pose2D, ComposeKnownValues) {
  const Pose2D a(1.0, 2.0, kPi / 2.0);
  const Pose2D b(3.0, 0.0, 0.0);
  expectPoseNear(a * b, Pose2D(1.0, 5.0, kPi / 2.0));
  expectPoseNear(b * a, Pose2D(4.0, 2.0, kPi / 2.0));

  const Eigen::Vector2d p = a * Eigen::Vector2d(1.0, 0.0);
  EXPECT_NEAR(p.x(), 1.0, kEps);
  EXPECT_NEAR(p.y(), 3.0, kEps);
  const Eigen::Vector2d q = Pose2D(0.5, -1.0, kPi) * Eigen::Vector2d(2.0, 1.0);
  EXPECT_NEAR(q.x(), -1.5, kEps);
  EXPECT_NEAR(q.y(), -2.0, kEps);
}

TEST(Pose2D, ComposeWrapsAcrossTheSeam) {
  const Pose2D result = Pose2D(0.0, 0.0, 3.0) * Pose2D(1.0, 0.0, 0.3);
  EXPECT_NEAR(result.theta, 3.3 - 2.0 * kPi, kEps);
  EXPECT_NEAR(result.x, std::cos(3.0), kEps);
  EXPECT_NEAR(result.y, std::sin(3.0), kEps);
  // Half a turn twice is a full turn: theta 0, not 2 pi.
  EXPECT_NEAR((Pose2D(0.0, 0.0, kPi) * Pose2D(0.0, 0.0, kPi)).theta, 0.0, kEps);
}

TEST(Pose2D, ComposeMatchesHandWrittenFormulaAndIsAssociative) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(-10.0, 10.0);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int i = 0; i < 1000; ++i) {
    const Pose2D a(coord(rng), coord(rng), angle(rng));
    const Pose2D b(coord(rng), coord(rng), angle(rng));
    const Pose2D c(coord(rng), coord(rng), angle(rng));
    expectPoseNear(a * b, hglasm_test::composeByHand(a, b), 1e-11);
    expectPoseNear((a * b) * c, a * (b * c), 1e-10);
    const Eigen::Vector2d point(coord(rng), coord(rng));
    const Eigen::Vector2d via_pose = (a * b) * point;
    const Eigen::Vector2d step_by_step = a * (b * point);
    EXPECT_NEAR((via_pose - step_by_step).norm(), 0.0, 1e-10);
  }
}

TEST(Pose2D, InverseUndoesCompose) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-10.0, 10.0);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int i = 0; i < 1000; ++i) {
    const Pose2D a(coord(rng), coord(rng), angle(rng));
    expectPoseNear(a * a.inverse(), Pose2D::identity(), 1e-11);
    expectPoseNear(a.inverse() * a, Pose2D::identity(), 1e-11);
    expectPoseNear(a.inverse().inverse(), a, 1e-11);
    const Eigen::Vector2d point(coord(rng), coord(rng));
    EXPECT_NEAR((a.inverse() * (a * point) - point).norm(), 0.0, 1e-10);
  }
  expectPoseNear(Pose2D(1.0, 0.0, kPi / 2.0).inverse(), Pose2D(0.0, 1.0, -kPi / 2.0));
  // The inverse of a half turn is a half turn, reported as +pi.
  EXPECT_NEAR(Pose2D(0.0, 0.0, kPi).inverse().theta, kPi, kEps);
}

TEST(Pose2D, RelativePose) {
  const Pose2D a(1.0, 1.0, kPi / 2.0);
  const Pose2D b(1.0, 3.0, kPi);
  // b is 2 m ahead of a (a looks along +y) and turned a further 90 degrees left.
  expectPoseNear(hglasm::relativePose(a, b), Pose2D(2.0, 0.0, kPi / 2.0));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coord(-10.0, 10.0);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int i = 0; i < 1000; ++i) {
    const Pose2D p(coord(rng), coord(rng), angle(rng));
    const Pose2D q(coord(rng), coord(rng), angle(rng));
    const Pose2D rel = hglasm::relativePose(p, q);
    expectPoseNear(rel, hglasm_test::relativeByHand(p, q), 1e-10);
    expectPoseNear(p * rel, q, 1e-10);
  }
}

TEST(Pose2D, RelativePoseAcrossTheSeam) {
  // Headings 179 and -179 degrees are 2 degrees apart, not 358.
  const Pose2D a(0.0, 0.0, hglasm_test::deg(179.0));
  const Pose2D b(0.0, 0.0, hglasm_test::deg(-179.0));
  EXPECT_NEAR(hglasm::relativePose(a, b).theta, hglasm_test::deg(2.0), 1e-12);
  EXPECT_NEAR(hglasm::relativePose(b, a).theta, hglasm_test::deg(-2.0), 1e-12);
}

TEST(Interpolate, EndpointsMidpointAndExtrapolation) {
  const Pose2D a(0.0, 0.0, 0.0);
  const Pose2D b(2.0, 4.0, 1.0);
  expectPoseNear(hglasm::interpolate(a, b, 0.0), a);
  expectPoseNear(hglasm::interpolate(a, b, 1.0), b);
  expectPoseNear(hglasm::interpolate(a, b, 0.5), Pose2D(1.0, 2.0, 0.5));
  expectPoseNear(hglasm::interpolate(a, b, 0.25), Pose2D(0.5, 1.0, 0.25));
  expectPoseNear(hglasm::interpolate(a, b, 2.0), Pose2D(4.0, 8.0, 2.0));
  expectPoseNear(hglasm::interpolate(a, b, -0.5), Pose2D(-1.0, -2.0, -0.5));
}

TEST(Interpolate, TakesTheShortestArcAcrossTheSeam) {
  const Pose2D a(0.0, 0.0, 3.0);
  const Pose2D b(1.0, 0.0, -3.0);  // 0.283 rad further counter-clockwise, across +pi
  const Pose2D mid = hglasm::interpolate(a, b, 0.5);
  EXPECT_NEAR(mid.x, 0.5, kEps);
  EXPECT_NEAR(angleDiff(mid.theta, kPi), 0.0, 1e-12);
  const Pose2D quarter = hglasm::interpolate(a, b, 0.25);
  EXPECT_NEAR(angleDiff(quarter.theta, 3.0 + 0.25 * (2.0 * kPi - 6.0)), 0.0, 1e-12);
  // And the other way round.
  const Pose2D back = hglasm::interpolate(b, a, 0.25);
  EXPECT_NEAR(angleDiff(back.theta, -3.0 - 0.25 * (2.0 * kPi - 6.0)), 0.0, 1e-12);
  EXPECT_GT(back.theta, -kPi);
  EXPECT_LE(back.theta, kPi);
}

TEST(Adjoint, MapsChildFrameMotionToParentFrame) {
  // pose * delta == (Ad * delta) * pose to first order in delta.
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> coord(-5.0, 5.0);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  const double h = 1e-6;
  for (int i = 0; i < 100; ++i) {
    const Pose2D pose(coord(rng), coord(rng), angle(rng));
    const Eigen::Matrix3d ad = hglasm::adjoint(pose);
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3d delta = Eigen::Vector3d::Zero();
      delta[axis] = h;
      const Pose2D moved = pose * Pose2D(delta[0], delta[1], delta[2]);
      const Pose2D parent_delta = moved * pose.inverse();
      const Eigen::Vector3d expected = ad * delta;
      EXPECT_NEAR(parent_delta.x, expected[0], 1e-10 + 1e-4 * h);
      EXPECT_NEAR(parent_delta.y, expected[1], 1e-10 + 1e-4 * h);
      EXPECT_NEAR(parent_delta.theta, expected[2], 1e-10 + 1e-4 * h);
    }
  }
  // The covariance of a motion keeps its size under a change of frame when the pose is a pure rotation.
  const Eigen::Matrix3d ad = hglasm::adjoint(Pose2D(0.0, 0.0, 0.7));
  const Eigen::Matrix3d cov = Eigen::Vector3d(1.0, 2.0, 0.5).asDiagonal();
  EXPECT_NEAR((ad * cov * ad.transpose()).trace(), cov.trace(), 1e-12);
}

}  // namespace
