// The wheel-odometry noise model: a random walk in distance, turn and time, and its online learning.
#include "hglasm_odometry/core/motion_model.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>

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

/// Feeds `count` increments whose true noise is `true_scale` times the nominal model; returns the model.
MotionNoiseModel learnFrom(double true_scale_xy, double true_scale_theta, int count, std::uint64_t seed) {
  MotionNoiseModel model;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  for (int i = 0; i < count; ++i) {
    const Pose2D step(0.05, 0.0, 0.02 * std::sin(0.1 * i));
    const Eigen::Vector3d nominal = model.nominalOdometryCovariance(step, 0.1).diagonal();
    const Eigen::Vector3d error(normal(rng) * std::sqrt(true_scale_xy * nominal.x()),
                                normal(rng) * std::sqrt(true_scale_xy * nominal.y()),
                                normal(rng) * std::sqrt(true_scale_theta * nominal.z()));
    model.learn(error, Eigen::Vector3d::Zero(), nominal);
  }
  return model;
}

TEST(MotionNoiseModel, LearnsGoodAndBadWheels) {
  // Good wheels (a tenth of the nominal variance) and bad ones (ten times): the learned scales find them.
  const MotionNoiseModel good = learnFrom(0.1, 0.2, 3000, 1);
  EXPECT_NEAR(good.scale().xy, 0.1, 0.03);
  EXPECT_NEAR(good.scale().theta, 0.2, 0.06);
  const MotionNoiseModel bad = learnFrom(10.0, 5.0, 3000, 2);
  EXPECT_NEAR(bad.scale().xy, 10.0, 3.0);
  EXPECT_NEAR(bad.scale().theta, 5.0, 1.5);
  // And the covariance it predicts follows.
  const Pose2D step(0.05, 0.0, 0.0);
  EXPECT_NEAR(bad.odometryCovariance(step, 0.1)(0, 0) / bad.nominalOdometryCovariance(step, 0.1)(0, 0),
              bad.scale().xy, 1e-12);
}

TEST(MotionNoiseModel, OneWildIncrementDoesNotTeachThatTheWheelsAreBad) {
  MotionNoiseModel model = learnFrom(1.0, 1.0, 500, 3);
  const double before = model.scale().xy;
  const Pose2D step(0.05, 0.0, 0.0);
  const Eigen::Vector3d nominal = model.nominalOdometryCovariance(step, 0.1).diagonal();
  model.learn(Eigen::Vector3d(5.0, 0.0, 0.0), Eigen::Vector3d::Zero(), nominal);  // a door swinging: 5 m
  EXPECT_LT(model.scale().xy, 1.2 * before);
}

TEST(MotionNoiseModel, ExplainedVarianceIsNotBlamedOnTheWheels) {
  // Innovations that are all the match's own noise leave the wheels at the smallest scale.
  MotionNoiseModel model;
  std::mt19937_64 rng(4);
  std::normal_distribution<double> normal;
  const Pose2D step(0.05, 0.0, 0.0);
  const Eigen::Vector3d nominal = model.nominalOdometryCovariance(step, 0.1).diagonal();
  const Eigen::Vector3d match_variance = 4.0 * nominal;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d error(normal(rng), normal(rng), normal(rng));
    model.learn(error.cwiseProduct(match_variance.cwiseSqrt()), match_variance, nominal);
  }
  EXPECT_LT(model.scale().xy, 0.3);
  EXPECT_LT(model.scale().theta, 0.3);
}

TEST(MotionNoiseModel, LearningCanBeTurnedOffAndReset) {
  MotionNoiseOptions options;
  options.learn = false;
  MotionNoiseModel fixed(options);
  fixed.learn(Eigen::Vector3d(1.0, 1.0, 1.0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1e-4));
  EXPECT_EQ(fixed.scale().xy, 1.0);
  EXPECT_EQ(fixed.scale().theta, 1.0);
  MotionNoiseModel learned = learnFrom(10.0, 10.0, 500, 5);
  EXPECT_GT(learned.scale().xy, 3.0);
  learned.resetLearning();
  EXPECT_EQ(learned.scale().xy, 1.0);
  // Non-finite input changes nothing.
  learned.learn(Eigen::Vector3d(std::nan(""), 0.0, 0.0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  EXPECT_EQ(learned.scale().xy, 1.0);
}

}  // namespace
