// The wheel-odometry noise model: a random walk in distance, turn and time (its scales are learned by
// NoiseLearner, test_noise_learner.cpp).
#include "hglasm_odometry/core/motion_model.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

namespace {

using hglasm::MotionNoiseModel;
using hglasm::MotionNoiseOptions;
using hglasm::Pose2D;

TEST(MotionNoiseModel, VariancesGrowLinearlyWithDistanceTurnAndTime) {
  MotionNoiseOptions options;
  options.xy_per_metre = 0.1;
  options.xy_per_radian = 0.2;
  options.xy_per_second = 0.03;
  options.theta_per_metre = 0.04;
  options.theta_per_radian = 0.05;
  options.theta_per_second = 0.06;
  options.systematic = 0.0;
  const MotionNoiseModel model(options);
  const Eigen::Matrix3d c = model.odometryCovariance(Pose2D(0.3, 0.4, -0.5), 2.0);  // 0.5 m, 0.5 rad, 2 s
  const double xy = 0.01 * 0.5 + 0.04 * 0.5 + 0.0009 * 2.0;
  const double theta = 0.0016 * 0.5 + 0.0025 * 0.5 + 0.0036 * 2.0;
  EXPECT_NEAR(c(0, 0), xy, 1e-15);
  EXPECT_NEAR(c(1, 1), xy, 1e-15);
  EXPECT_NEAR(c(2, 2), theta, 1e-15);
  EXPECT_EQ(c(0, 1), 0.0);
  EXPECT_EQ(c(0, 2), 0.0);
  // Twice the step, twice the variance: composing steps adds up like one long one.
  const Eigen::Matrix3d twice = model.odometryCovariance(Pose2D(0.6, 0.8, -1.0), 4.0);
  EXPECT_NEAR(twice(0, 0), 2.0 * xy, 1e-15);
  EXPECT_NEAR(twice(2, 2), 2.0 * theta, 1e-15);
}

TEST(MotionNoiseModel, SystematicErrorsGrowWithTheStepNotItsRoot) {
  // A wheel radius 1 % off miscounts 1 % of every distance: over a 100 m step (the wheels across a long
  // pause) that is 1 m, where the random walk alone would claim a few centimetres.
  MotionNoiseOptions options;
  options.systematic = 0.01;
  const MotionNoiseModel model(options);
  const Pose2D long_step(100.0, 0.0, 2.0);
  const Eigen::Matrix3d systematic = model.systematicCovariance(long_step);
  EXPECT_NEAR(std::sqrt(systematic(0, 0)), 1.0, 1e-12);
  EXPECT_NEAR(std::sqrt(systematic(2, 2)), 0.02, 1e-12);
  hglasm::MotionNoiseModel learned(options);
  learned.setScale({1e-4, 1e-4});  // wheels learned to be nearly exact step by step
  const Eigen::Matrix3d covariance = learned.odometryCovariance(long_step, 200.0);
  EXPECT_GT(std::sqrt(covariance(0, 0)), 1.0) << "never less than the systematic part";
  EXPECT_NEAR(covariance(0, 0) - systematic(0, 0),
              1e-4 * model.nominalOdometryCovariance(long_step, 200.0)(0, 0), 1e-12);
}

TEST(MotionNoiseModel, StandingStillIsNeverExactlyCertain) {
  MotionNoiseOptions options;
  options.xy_per_second = options.theta_per_second = 0.0;
  const Eigen::Matrix3d c = MotionNoiseModel(options).odometryCovariance(Pose2D(), 0.0);
  EXPECT_GT(c.determinant(), 0.0) << "a prior's covariance must stay invertible";
  EXPECT_TRUE(MotionNoiseModel().odometryCovariance(Pose2D(), std::nan("")).allFinite());
}

TEST(MotionNoiseModel, ConstantVelocityGuessIsOffByTheVelocityErrorAndTheAcceleration) {
  MotionNoiseOptions options;
  options.constant_velocity_xy = 1.0;
  options.constant_velocity_theta = 2.0;
  options.constant_velocity_velocity_xy = 0.2;
  options.constant_velocity_velocity_theta = 0.3;
  const MotionNoiseModel model(options);
  // 0.1 s: mostly the velocity's error (0.02 m, 0.03 rad), a little acceleration (0.005 m, 0.01 rad).
  Eigen::Matrix3d c = model.constantVelocityCovariance(0.1);
  EXPECT_NEAR(std::sqrt(c(0, 0)), std::hypot(0.02, 0.005), 1e-12);
  EXPECT_NEAR(std::sqrt(c(1, 1)), std::hypot(0.02, 0.005), 1e-12);
  EXPECT_NEAR(std::sqrt(c(2, 2)), std::hypot(0.03, 0.01), 1e-12);
  // 2 s: mostly the acceleration (2 m, 4 rad beside 0.4 m, 0.6 rad).
  c = model.constantVelocityCovariance(2.0);
  EXPECT_NEAR(std::sqrt(c(0, 0)), std::hypot(0.4, 2.0), 1e-12);
  EXPECT_NEAR(std::sqrt(c(2, 2)), std::hypot(0.6, 4.0), 1e-12);
  EXPECT_GT(model.constantVelocityCovariance(0.0).determinant(), 0.0) << "stays invertible";
}

}  // namespace
