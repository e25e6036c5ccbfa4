// The prediction of the base's motion between scans (wheel odometry when it covers both stamps and moves
// plausibly, else the velocity of the recent estimates) and that velocity: its baseline, its frame, its
// caps and when it is forgotten. Exact answers on synthetic poses.
#include "hglasm_odometry/core/pose_extrapolator.h"

#include <gtest/gtest.h>

#include <string>

#include "test_util.h"

namespace {

using hglasm::MotionNoiseModel;
using hglasm::MotionPrediction;
using hglasm::Pose2D;
using hglasm::PoseExtrapolator;
using hglasm::PredictionSource;
using hglasm_test::kPi;

constexpr double kMaxSpeed = 2.0;     // m/s
constexpr double kMaxTurnRate = 1.0;  // rad/s
constexpr double kOdometryAge = 0.5;  // s

hglasm::PoseExtrapolatorOptions extrapolatorOptions(bool use_odometry) {
  hglasm::PoseExtrapolatorOptions options;
  options.use_odometry = use_odometry;
  options.max_odometry_extrapolation = kOdometryAge;
  options.max_speed = kMaxSpeed;
  options.max_turn_rate = kMaxTurnRate;
  return options;
}

PoseExtrapolator makeExtrapolator(bool use_odometry = true) {
  return PoseExtrapolator(extrapolatorOptions(use_odometry));
}

void expectPose(const Pose2D& actual, double x, double y, double theta, double tolerance = 1e-12) {
  EXPECT_NEAR(actual.x, x, tolerance);
  EXPECT_NEAR(actual.y, y, tolerance);
  EXPECT_NEAR(hglasm_test::angleDiff(actual.theta, theta), 0.0, tolerance);
}

TEST(PoseExtrapolator, NothingKnownPredictsNoMotionWithConstantVelocityNoise) {
  const PoseExtrapolator extrapolator = makeExtrapolator();
  const MotionNoiseModel noise;
  std::string warning;
  const MotionPrediction prediction = extrapolator.predict(1.0, 1.5, noise, &warning);
  EXPECT_EQ(prediction.source, PredictionSource::kNone);
  expectPose(prediction.motion, 0.0, 0.0, 0.0, 0.0);
  EXPECT_EQ(prediction.covariance, noise.constantVelocityCovariance(0.5));
  EXPECT_EQ(prediction.nominal_covariance, Eigen::Matrix3d::Zero());
  EXPECT_TRUE(warning.empty());
  EXPECT_FALSE(extrapolator.velocityKnown());
}

TEST(PoseExtrapolator, OdometryPredictsTheMotionInTheBaseFrame) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  // Facing +y, the base moves 1 m towards -y: backwards in its own frame, and turns 0.5 rad.
  extrapolator.addOdometry(1.0, Pose2D(1.0, 2.0, kPi / 2));
  extrapolator.addOdometry(2.0, Pose2D(1.0, 1.0, kPi / 2 + 0.5));
  const MotionNoiseModel noise;
  std::string warning;
  const MotionPrediction prediction = extrapolator.predict(1.0, 2.0, noise, &warning);
  EXPECT_EQ(prediction.source, PredictionSource::kOdometry);
  expectPose(prediction.motion, -1.0, 0.0, 0.5);
  EXPECT_EQ(prediction.covariance, noise.odometryCovariance(prediction.motion, 1.0));
  EXPECT_EQ(prediction.nominal_covariance, noise.nominalOdometryCovariance(prediction.motion, 1.0));
  EXPECT_TRUE(warning.empty());
}

TEST(PoseExtrapolator, OdometryIsInterpolatedToTheStamps) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(1.0, Pose2D(1.0, 0.0, 0.0));
  std::string warning;
  const MotionPrediction prediction = extrapolator.predict(0.25, 0.75, MotionNoiseModel(), &warning);
  EXPECT_EQ(prediction.source, PredictionSource::kOdometry);
  expectPose(prediction.motion, 0.5, 0.0, 0.0, 0.0);
}

TEST(PoseExtrapolator, WheelJumpFallsBackWithAWarning) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  // 2 m/s over 1 s plus 0.2 m of margin is the most the wheels may move: 2.3 m is a jump, 2.1 m is not.
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(1.0, Pose2D(2.1, 0.0, 0.0));
  extrapolator.addOdometry(2.0, Pose2D(4.4, 0.0, 0.0));
  const MotionNoiseModel noise;
  std::string warning;
  EXPECT_EQ(extrapolator.predict(0.0, 1.0, noise, &warning).source, PredictionSource::kOdometry);
  EXPECT_TRUE(warning.empty());
  const MotionPrediction jumped = extrapolator.predict(1.0, 2.0, noise, &warning);
  EXPECT_EQ(jumped.source, PredictionSource::kNone);
  expectPose(jumped.motion, 0.0, 0.0, 0.0, 0.0);
  EXPECT_EQ(jumped.covariance, noise.constantVelocityCovariance(1.0));
  EXPECT_NE(warning.find("wheel odometry jumped"), std::string::npos) << warning;
}

TEST(PoseExtrapolator, WheelTurnJumpFallsBack) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  // 1 rad/s over 0.5 s plus 0.2 rad of margin: 0.8 rad is a jump.
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(0.5, Pose2D(0.0, 0.0, 0.8));
  std::string warning;
  EXPECT_EQ(extrapolator.predict(0.0, 0.5, MotionNoiseModel(), &warning).source, PredictionSource::kNone);
  EXPECT_FALSE(warning.empty());
}

TEST(PoseExtrapolator, OdometryIgnoredWhenDisabledStaleOrCleared) {
  const MotionNoiseModel noise;
  std::string warning;
  PoseExtrapolator disabled = makeExtrapolator(false);
  disabled.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  disabled.addOdometry(1.0, Pose2D(1.0, 0.0, 0.0));
  EXPECT_EQ(disabled.predict(0.0, 1.0, noise, &warning).source, PredictionSource::kNone);

  PoseExtrapolator extrapolator = makeExtrapolator();
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(1.0, Pose2D(1.0, 0.0, 0.0));
  // The newest sample may be extrapolated 0.5 s, not 0.6 s.
  EXPECT_EQ(extrapolator.predict(0.0, 1.5, noise, &warning).source, PredictionSource::kOdometry);
  EXPECT_EQ(extrapolator.predict(0.0, 1.6, noise, &warning).source, PredictionSource::kNone);
  extrapolator.clearOdometry();
  EXPECT_EQ(extrapolator.predict(0.0, 1.0, noise, &warning).source, PredictionSource::kNone);
  EXPECT_TRUE(warning.empty());
}

TEST(PoseExtrapolator, TheWheelsAreReadAtTheScansStampPlusTheirTimeOffset) {
  // Wheels 0.3 s late: their pose of the scans' 1.0 s is the one stamped 1.3 s.
  const MotionNoiseModel noise;
  std::string warning;
  PoseExtrapolator extrapolator = makeExtrapolator();
  for (int i = 0; i <= 20; ++i) extrapolator.addOdometry(0.1 * i, Pose2D(0.1 * i * 0.1 * i, 0.0, 0.0));
  extrapolator.setOdometryTimeOffset(0.3);
  EXPECT_EQ(extrapolator.odometryTimeOffset(), 0.3);
  const MotionPrediction late = extrapolator.predict(0.5, 1.0, noise, &warning);
  ASSERT_EQ(late.source, PredictionSource::kOdometry);
  expectPose(late.motion, 1.3 * 1.3 - 0.8 * 0.8, 0.0, 0.0, 1e-9);
}

TEST(PoseExtrapolator, WithoutWheelsALongPauseKeepsThePose) {
  // The velocity is no longer known after kMaxVelocityAge: no motion is predicted over a longer step, and
  // its noise is that of kMaxVelocityAge (the search is the preset's box).
  const MotionNoiseModel noise;
  std::string warning;
  hglasm::PoseExtrapolatorOptions options;
  options.use_odometry = false;
  options.max_odometry_extrapolation = 0.5;
  PoseExtrapolator extrapolator(options);
  extrapolator.addPose(0.0, Pose2D());
  extrapolator.addPose(0.5, Pose2D(0.5, 0.0, 0.0));
  ASSERT_TRUE(extrapolator.velocityKnown());
  const MotionPrediction short_step = extrapolator.predict(0.5, 1.5, noise, &warning);
  EXPECT_EQ(short_step.source, PredictionSource::kConstantVelocity);
  expectPose(short_step.motion, 1.0, 0.0, 0.0);
  const MotionPrediction pause = extrapolator.predict(0.5, 100.5, noise, &warning);
  EXPECT_EQ(pause.source, PredictionSource::kNone);
  expectPose(pause.motion, 0.0, 0.0, 0.0);
  EXPECT_EQ(pause.covariance, noise.constantVelocityCovariance(PoseExtrapolator::kMaxVelocityAge));
}

PoseExtrapolator makeImuExtrapolator(bool use_odometry = true) {
  hglasm::PoseExtrapolatorOptions options = extrapolatorOptions(use_odometry);
  options.use_imu = true;
  options.imu.angle_random_walk = 0.01;
  options.imu.bias_sigma = 0.02;
  options.imu.scale_error = 0.03;
  return PoseExtrapolator(options);
}

TEST(PoseExtrapolator, TheGyroGivesTheRotationAndTurnsTheWheelsChordWithIt) {
  PoseExtrapolator extrapolator = makeImuExtrapolator();
  // The wheels: 1 m straight ahead, no turn. The gyro: 0.8 rad/s for 0.5 s, 0.4 rad. The chord of the arc
  // turns by half the rotation: (cos 0.2, sin 0.2).
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(0.5, Pose2D(1.0, 0.0, 0.0));
  for (int i = 0; i <= 50; ++i) EXPECT_TRUE(extrapolator.addImu(0.01 * i, 0.8));
  const MotionNoiseModel noise;
  std::string warning;
  const MotionPrediction prediction = extrapolator.predict(0.0, 0.5, noise, &warning);
  EXPECT_EQ(prediction.source, PredictionSource::kOdometry);
  EXPECT_TRUE(prediction.rotation_from_imu);
  expectPose(prediction.motion, std::cos(0.2), std::sin(0.2), 0.4);
  // First order: the wheels' translation noise turned with the chord (theirs is isotropic here), and the
  // gyro's heading noise, which also moves the chord by half of it across the chord; the wheels' nominal
  // heading variance is zero (their heading is not what was predicted, so not learned from).
  const double heading_variance = 0.01 * 0.01 * 0.5 + 0.01 * 0.01 + 0.012 * 0.012;
  const Eigen::Vector3d chord_per_radian(-0.5 * std::sin(0.2), 0.5 * std::cos(0.2), 1.0);
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected.topLeftCorner<2, 2>() = noise.odometryCovariance(Pose2D(1.0, 0.0, 0.0), 0.5).topLeftCorner<2, 2>();
  expected += heading_variance * chord_per_radian * chord_per_radian.transpose();
  EXPECT_TRUE(prediction.covariance.isApprox(expected, 1e-12)) << prediction.covariance << "\n" << expected;
  EXPECT_EQ(prediction.nominal_covariance(2, 2), 0.0);
  EXPECT_EQ(prediction.nominal_covariance(0, 2), 0.0);
  EXPECT_GT(prediction.nominal_covariance(0, 0), 0.0);
}

TEST(PoseExtrapolator, TheChordIsTurnedTheShortWayForTurnsBeyondPiAndToTheRight) {
  // 3.3 rad in 4 s (the wheels' heading wraps to 3.3 - 2 pi, the gyro's does not): both agree, so the
  // chord, at half the rotation, stays where the wheels put it.
  PoseExtrapolator extrapolator = makeImuExtrapolator();
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(4.0, Pose2D(std::cos(1.65), std::sin(1.65), 3.3));
  for (int i = 0; i <= 400; ++i) extrapolator.addImu(0.01 * i, 3.3 / 4.0);
  const MotionNoiseModel noise;
  std::string warning;
  const MotionPrediction wide = extrapolator.predict(0.0, 4.0, noise, &warning);
  ASSERT_TRUE(wide.rotation_from_imu) << warning;
  expectPose(wide.motion, std::cos(1.65), std::sin(1.65), 3.3, 1e-9);

  // To the right: the wheels turn -0.2 rad, the gyro -0.4: the chord turns by -0.1 more.
  PoseExtrapolator right = makeImuExtrapolator();
  right.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  right.addOdometry(0.5, Pose2D(std::cos(-0.1), std::sin(-0.1), -0.2));
  for (int i = 0; i <= 50; ++i) right.addImu(0.01 * i, -0.8);
  const MotionPrediction turned = right.predict(0.0, 0.5, noise, &warning);
  ASSERT_TRUE(turned.rotation_from_imu);
  expectPose(turned.motion, std::cos(-0.2), std::sin(-0.2), -0.4, 1e-9);
}

TEST(PoseExtrapolator, AnImplausiblyFastGyroIsNotUsedAndSaysSo) {
  PoseExtrapolator extrapolator = makeImuExtrapolator();
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(0.5, Pose2D(1.0, 0.0, 0.1));
  for (int i = 0; i <= 50; ++i) extrapolator.addImu(0.01 * i, 20.0);  // 10 rad in 0.5 s: a spike
  std::string warning;
  const MotionPrediction prediction = extrapolator.predict(0.0, 0.5, MotionNoiseModel(), &warning);
  EXPECT_FALSE(prediction.rotation_from_imu);
  expectPose(prediction.motion, 1.0, 0.0, 0.1);
  EXPECT_NE(warning.find("IMU rotation"), std::string::npos) << warning;
}

TEST(PoseExtrapolator, WithoutWheelsTheGyroTurnsTheConstantVelocityPrediction) {
  PoseExtrapolator extrapolator = makeImuExtrapolator(false);
  extrapolator.addPose(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addPose(0.5, Pose2D(0.5, 0.0, 0.0));  // 1 m/s straight
  for (int i = 0; i <= 100; ++i) extrapolator.addImu(0.01 * i, -1.0);
  std::string warning;
  const MotionPrediction prediction = extrapolator.predict(0.5, 0.7, MotionNoiseModel(), &warning);
  EXPECT_EQ(prediction.source, PredictionSource::kConstantVelocity);
  EXPECT_TRUE(prediction.rotation_from_imu);
  expectPose(prediction.motion, 0.2 * std::cos(-0.1), 0.2 * std::sin(-0.1), -0.2);
}

TEST(PoseExtrapolator, StaleOrMissingGyroLeavesTheWheelsPrediction) {
  PoseExtrapolator extrapolator = makeImuExtrapolator();
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(1.0, Pose2D(1.0, 0.0, 0.3));
  const MotionNoiseModel noise;
  std::string warning;
  const MotionPrediction missing = extrapolator.predict(0.0, 1.0, noise, &warning);
  EXPECT_FALSE(missing.rotation_from_imu);
  expectPose(missing.motion, 1.0, 0.0, 0.3);
  EXPECT_EQ(missing.covariance, noise.odometryCovariance(missing.motion, 1.0));
  for (int i = 0; i <= 50; ++i) extrapolator.addImu(0.01 * i, 1.0);  // stops at 0.5 s
  const MotionPrediction stale = extrapolator.predict(0.0, 1.0, noise, &warning);
  EXPECT_FALSE(stale.rotation_from_imu);
  expectPose(stale.motion, 1.0, 0.0, 0.3);
  EXPECT_TRUE(extrapolator.predict(0.0, 0.55, noise, &warning).rotation_from_imu)
      << "within max_gap of the newest sample";
  extrapolator.clearImu();
  EXPECT_FALSE(extrapolator.predict(0.0, 0.5, noise, &warning).rotation_from_imu) << "cleared";
}

TEST(PoseExtrapolator, ImuSamplesAreIgnoredWithoutUseImu) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  EXPECT_FALSE(extrapolator.addImu(0.0, 1.0));
  EXPECT_FALSE(extrapolator.addImu(0.1, 1.0));
  std::string warning;
  EXPECT_FALSE(extrapolator.predict(0.0, 0.1, MotionNoiseModel(), &warning).rotation_from_imu);
}

TEST(PoseExtrapolator, VelocityNeedsABaselineOfATenthOfASecond) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  // 1.5 m/s along x; stamps and positions exact in binary.
  EXPECT_EQ(extrapolator.addPose(0.0, Pose2D(0.0, 0.0, 0.0)), 0.0);
  EXPECT_EQ(extrapolator.addPose(0.0625, Pose2D(0.09375, 0.0, 0.0)), 0.0);
  EXPECT_FALSE(extrapolator.velocityKnown());
  // The oldest pose is dropped once the next one alone spans the baseline: 0.25 - 0.0625 >= 0.1.
  EXPECT_EQ(extrapolator.addPose(0.25, Pose2D(0.375, 0.0, 0.0)), 0.1875);
  ASSERT_TRUE(extrapolator.velocityKnown());
  EXPECT_EQ(extrapolator.velocity(), Eigen::Vector3d(1.5, 0.0, 0.0));
}

TEST(PoseExtrapolator, VelocityIsInTheBaseFrame) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  // Facing +y and moving along +y while turning: forward in its own frame at the start of the baseline.
  extrapolator.addPose(0.0, Pose2D(3.0, 4.0, kPi / 2));
  EXPECT_EQ(extrapolator.addPose(0.5, Pose2D(3.0, 4.5, kPi / 2 + 0.25)), 0.5);
  ASSERT_TRUE(extrapolator.velocityKnown());
  EXPECT_NEAR(extrapolator.velocity().x(), 1.0, 1e-12);
  EXPECT_NEAR(extrapolator.velocity().y(), 0.0, 1e-12);
  EXPECT_NEAR(extrapolator.velocity().z(), 0.5, 1e-12);
}

TEST(PoseExtrapolator, VelocityIsCappedAtThePlausibleSpeeds) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  // 6 m/s and 8 m/s sideways (10 m/s) become 2 m/s in the same direction; -3 rad/s becomes -1 rad/s.
  extrapolator.addPose(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addPose(0.5, Pose2D(3.0, 4.0, -1.5));
  ASSERT_TRUE(extrapolator.velocityKnown());
  EXPECT_NEAR(extrapolator.velocity().x(), 1.2, 1e-12);
  EXPECT_NEAR(extrapolator.velocity().y(), 1.6, 1e-12);
  EXPECT_EQ(extrapolator.velocity().z(), -kMaxTurnRate);
}

TEST(PoseExtrapolator, VelocityPredictsWithoutOdometry) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  extrapolator.addPose(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addPose(0.5, Pose2D(0.5, -0.25, 0.125));
  const MotionNoiseModel noise;
  std::string warning;
  const MotionPrediction prediction = extrapolator.predict(0.5, 0.75, noise, &warning);
  EXPECT_EQ(prediction.source, PredictionSource::kConstantVelocity);
  // (1, -0.5, 0.25) per second, times 0.25 s.
  expectPose(prediction.motion, 0.25, -0.125, 0.0625, 0.0);
  EXPECT_EQ(prediction.covariance, noise.constantVelocityCovariance(0.25));
  EXPECT_EQ(prediction.nominal_covariance, Eigen::Matrix3d::Zero());
}

TEST(PoseExtrapolator, OldMotionIsForgotten) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  extrapolator.addPose(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addPose(0.5, Pose2D(0.5, 0.0, 0.0));
  ASSERT_TRUE(extrapolator.velocityKnown());
  // 2.5 s since the previous estimate: longer than kMaxVelocityAge, the speed now is unknown.
  EXPECT_EQ(extrapolator.addPose(3.0, Pose2D(0.5, 0.0, 0.0)), 0.0);
  EXPECT_FALSE(extrapolator.velocityKnown());
  // The next estimate measures it again over the 0.25 s since.
  EXPECT_EQ(extrapolator.addPose(3.25, Pose2D(0.75, 0.0, 0.0)), 0.25);
  EXPECT_TRUE(extrapolator.velocityKnown());
  EXPECT_EQ(extrapolator.velocity(), Eigen::Vector3d(1.0, 0.0, 0.0));
}

TEST(PoseExtrapolator, ResetForgetsTheVelocityNotTheOdometry) {
  PoseExtrapolator extrapolator = makeExtrapolator();
  extrapolator.addOdometry(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addOdometry(1.0, Pose2D(1.0, 0.0, 0.0));
  extrapolator.addPose(0.0, Pose2D(0.0, 0.0, 0.0));
  extrapolator.addPose(0.5, Pose2D(0.5, 0.0, 0.0));
  ASSERT_TRUE(extrapolator.velocityKnown());
  extrapolator.reset();
  EXPECT_FALSE(extrapolator.velocityKnown());
  EXPECT_EQ(extrapolator.velocity(), Eigen::Vector3d::Zero());
  std::string warning;
  EXPECT_EQ(extrapolator.predict(0.0, 1.0, MotionNoiseModel(), &warning).source, PredictionSource::kOdometry);
  // The poses before the reset are gone: one new estimate gives no baseline.
  EXPECT_EQ(extrapolator.addPose(0.75, Pose2D(0.0, 0.0, 0.0)), 0.0);
}

TEST(PoseExtrapolator, SourceNames) {
  EXPECT_STREQ(hglasm::toString(PredictionSource::kOdometry), "odometry");
  EXPECT_STREQ(hglasm::toString(PredictionSource::kConstantVelocity), "constant_velocity");
  EXPECT_STREQ(hglasm::toString(PredictionSource::kNone), "none");
}

}  // namespace
