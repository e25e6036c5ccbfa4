// The IMU's rotation between two stamps: the yaw rate integrated exactly along its linear interpolation,
// the yaw's difference across the +-pi seam and over whole turns, stale and missing data, the noise model.
#include "hglasm_odometry/core/gyro.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test_util.h"

namespace {

using hglasm::GyroBuffer;
using hglasm::GyroOptions;
using hglasm_test::kPi;

GyroOptions rateOptions(double max_gap = 0.1) {
  GyroOptions options;
  options.max_gap = max_gap;
  return options;
}

GyroOptions yawOptions() {
  GyroOptions options = rateOptions();
  options.use_orientation = true;
  return options;
}

TEST(GyroBuffer, AConstantRateIntegratesToRateTimesInterval) {
  GyroBuffer gyro(rateOptions());
  for (int i = 0; i <= 100; ++i) ASSERT_TRUE(gyro.add(0.01 * i, 2.0));
  double angle = 0.0;
  ASSERT_TRUE(gyro.rotation(0.123, 0.456, &angle));
  EXPECT_NEAR(angle, 2.0 * (0.456 - 0.123), 1e-12);
  ASSERT_TRUE(gyro.rotation(0.3, 0.3, &angle));
  EXPECT_EQ(angle, 0.0);
}

TEST(GyroBuffer, ALinearRateIntegratesExactlyBetweenAndAcrossSamples) {
  // rate = 3 t at 20 Hz: the integral of the linear interpolation is exact, 1.5 (b^2 - a^2).
  GyroBuffer gyro(rateOptions());
  for (int i = 0; i <= 40; ++i) gyro.add(0.05 * i, 3.0 * 0.05 * i);
  double angle = 0.0;
  ASSERT_TRUE(gyro.rotation(0.512, 1.377, &angle));
  EXPECT_NEAR(angle, 1.5 * (1.377 * 1.377 - 0.512 * 0.512), 1e-12);
  ASSERT_TRUE(gyro.rotation(0.51, 0.52, &angle));  // between two samples
  EXPECT_NEAR(angle, 1.5 * (0.52 * 0.52 - 0.51 * 0.51), 1e-12);
}

TEST(GyroBuffer, OutOfOrderSamplesGiveTheSameRotation) {
  GyroBuffer ordered(rateOptions()), shuffled(rateOptions());
  for (int i = 0; i <= 20; ++i) ordered.add(0.01 * i, std::sin(0.3 * i));
  for (int i = 20; i >= 0; i -= 2) shuffled.add(0.01 * i, std::sin(0.3 * i));
  for (int i = 1; i <= 20; i += 2) shuffled.add(0.01 * i, std::sin(0.3 * i));
  double a = 0.0, b = 0.0;
  ASSERT_TRUE(ordered.rotation(0.015, 0.185, &a));
  ASSERT_TRUE(shuffled.rotation(0.015, 0.185, &b));
  EXPECT_EQ(a, b);
}

TEST(GyroBuffer, BeyondTheSamplesTheEndRateIsHeldForAtMostTheMaximumGap) {
  GyroBuffer gyro(rateOptions(0.1));
  for (int i = 0; i <= 10; ++i) gyro.add(1.0 + 0.01 * i, 1.0);  // 1.0 .. 1.1 s
  double angle = 0.0;
  ASSERT_TRUE(gyro.rotation(1.05, 1.18, &angle));
  EXPECT_NEAR(angle, 0.13, 1e-12);
  ASSERT_TRUE(gyro.rotation(0.95, 1.05, &angle));
  EXPECT_NEAR(angle, 0.10, 1e-12);
  EXPECT_FALSE(gyro.rotation(1.05, 1.25, &angle)) << "0.15 s past the newest sample is stale";
  EXPECT_FALSE(gyro.rotation(0.85, 1.05, &angle)) << "0.15 s before the oldest sample is not covered";
}

TEST(GyroBuffer, AGapLongerThanTheMaximumInsideOrAroundTheIntervalIsNotCovered) {
  GyroBuffer gyro(rateOptions(0.1));
  for (int i = 0; i <= 10; ++i) gyro.add(0.01 * i, 1.0);        // 0 .. 0.1 s
  for (int i = 0; i <= 10; ++i) gyro.add(0.5 + 0.01 * i, 1.0);  // 0.5 .. 0.6 s: a 0.4 s gap
  double angle = 0.0;
  EXPECT_FALSE(gyro.rotation(0.05, 0.55, &angle));
  EXPECT_FALSE(gyro.rotation(0.2, 0.3, &angle)) << "inside the gap, no sample between the stamps";
  EXPECT_TRUE(gyro.rotation(0.02, 0.08, &angle));
  EXPECT_TRUE(gyro.rotation(0.5, 0.58, &angle)) << "the gap ends at the interval's start";
}

TEST(GyroBuffer, NonFiniteSamplesAndStampsAreRejected) {
  GyroBuffer gyro(rateOptions());
  EXPECT_FALSE(gyro.add(std::numeric_limits<double>::quiet_NaN(), 1.0));
  EXPECT_FALSE(gyro.add(0.0, std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(gyro.empty());
  double angle = 0.0;
  EXPECT_FALSE(gyro.rotation(0.0, 0.1, &angle)) << "no samples";
  gyro.add(0.0, 1.0);
  gyro.add(0.05, 1.0);
  EXPECT_FALSE(gyro.rotation(0.05, 0.0, &angle)) << "backwards";
  EXPECT_FALSE(gyro.rotation(0.0, std::numeric_limits<double>::quiet_NaN(), &angle));
}

TEST(GyroBuffer, YawDifferencesCrossThePiSeamAndCountWholeTurns) {
  // Turning at 4 rad/s, the yaw wrapped into (-pi, pi], sampled at 100 Hz: 1 s is 4 rad, 2 s more than a
  // whole turn.
  GyroBuffer gyro(yawOptions());
  for (int i = 0; i <= 300; ++i) gyro.add(0.01 * i, std::remainder(3.0 + 4.0 * 0.01 * i, 2.0 * kPi));
  double angle = 0.0;
  ASSERT_TRUE(gyro.rotation(0.005, 1.005, &angle));
  EXPECT_NEAR(angle, 4.0, 1e-9);
  ASSERT_TRUE(gyro.rotation(0.5, 2.5, &angle));
  EXPECT_NEAR(angle, 8.0, 1e-9);
}

TEST(GyroBuffer, ClearForgetsEverySample) {
  GyroBuffer gyro(rateOptions());
  gyro.add(0.0, 1.0);
  gyro.add(0.05, 1.0);
  gyro.clear();
  double angle = 0.0;
  EXPECT_FALSE(gyro.rotation(0.0, 0.05, &angle));
}

TEST(GyroBuffer, OnlyTheLastSecondsAreKept) {
  GyroBuffer gyro(rateOptions());
  for (int i = 0; i <= 2000; ++i) gyro.add(0.01 * i, 1.0);  // 20 s
  double angle = 0.0;
  EXPECT_FALSE(gyro.rotation(5.0, 5.1, &angle)) << "older than kKeptSeconds behind the newest sample";
  EXPECT_TRUE(gyro.rotation(19.0, 19.1, &angle));
}

TEST(GyroRotationVariance, AddsRandomWalkBiasAndScaleError) {
  GyroOptions options;
  options.angle_random_walk = 0.01;
  options.scale_error = 0.03;
  const double bias_variance = 0.02 * 0.02;
  EXPECT_NEAR(hglasm::gyroRotationVariance(options, 0.5, 2.0, bias_variance),
              0.01 * 0.01 * 2.0 + (0.02 * 2.0) * (0.02 * 2.0) + (0.03 * 0.5) * (0.03 * 0.5), 1e-15);
  EXPECT_NEAR(hglasm::gyroRotationVariance(options, -0.5, 2.0, bias_variance),
              hglasm::gyroRotationVariance(options, 0.5, 2.0, bias_variance), 1e-18);
  options = GyroOptions();
  options.angle_random_walk = options.bias = options.scale_error = 0.0;
  EXPECT_GT(hglasm::gyroRotationVariance(options, 1.0, 1.0, 0.0), 0.0) << "stays invertible";
  EXPECT_TRUE(
      std::isfinite(hglasm::gyroRotationVariance(GyroOptions(), std::numeric_limits<double>::quiet_NaN(),
                                                 -1.0, std::numeric_limits<double>::quiet_NaN())));
}

/// Steps of 0.1 s with a gyro of constant `bias`, noise-free scans and a standing robot: the
/// prediction is what the estimator's current bias makes of the gyro.
double learnBias(hglasm::GyroBiasEstimator* estimator, double bias, int steps, double rotation = 0.0) {
  for (int i = 0; i < steps; ++i) {
    const double predicted = rotation + (bias - estimator->bias()) * 0.1;
    estimator->update(predicted, rotation, 0.002 * 0.002, 0.1);
  }
  return estimator->bias();
}

TEST(GyroBiasEstimator, StartsUnknownAndLearnsAConstantBias) {
  GyroOptions options;
  hglasm::GyroBiasEstimator estimator(options);
  EXPECT_EQ(estimator.bias(), 0.0);
  EXPECT_EQ(estimator.variance(), options.bias * options.bias);
  // Each 0.1 s step sees 0.4 mrad of bias under 2 mrad of scan noise: the prior weighs as much as 18
  // steps, so after 300 the estimate has 300 / 318 of the bias.
  EXPECT_NEAR(learnBias(&estimator, 0.004, 300), 0.004 * 300.0 / 318.0, 5e-5) << "30 s standing";
  EXPECT_LT(estimator.variance(), 0.1 * options.bias * options.bias) << "and knows it";
  EXPECT_NEAR(learnBias(&estimator, 0.004, 300, 0.3), 0.004, 2e-4) << "30 s more, turning";
}

TEST(GyroBiasEstimator, ABiasFarOutsideThePriorIsStillLearnedStepByStep) {
  // 0.05 rad/s is ten standard deviations of the default prior: each step's innovation is clipped at the
  // gate, and the estimate walks there anyway.
  hglasm::GyroBiasEstimator estimator;
  EXPECT_NEAR(learnBias(&estimator, 0.05, 600), 0.05, 2e-3);
}

TEST(GyroBiasEstimator, OneBadMatchMovesTheLearnedBiasLittle) {
  hglasm::GyroBiasEstimator estimator;
  learnBias(&estimator, 0.0, 300);
  estimator.update(0.0, 0.5, 0.002 * 0.002, 0.1);  // the scans claim half a radian the gyro never saw
  EXPECT_LT(std::abs(estimator.bias()), 0.003);
}

TEST(GyroBiasEstimator, IgnoresInvalidStepsAndCanBeTurnedOffAndReset) {
  hglasm::GyroBiasEstimator estimator;
  EXPECT_FALSE(estimator.update(0.1, 0.0, 1e-6, 0.0));
  EXPECT_FALSE(estimator.update(std::nan(""), 0.0, 1e-6, 0.1));
  EXPECT_FALSE(estimator.update(0.1, 0.0, -1.0, 0.1));
  EXPECT_EQ(estimator.bias(), 0.0);
  learnBias(&estimator, 0.004, 100);
  estimator.reset();
  EXPECT_EQ(estimator.bias(), 0.0);
  GyroOptions off;
  off.estimate_bias = false;
  hglasm::GyroBiasEstimator fixed(off);
  EXPECT_FALSE(fixed.update(0.01, 0.0, 1e-6, 0.1));
  EXPECT_EQ(learnBias(&fixed, 0.004, 10), 0.0);
}

}  // namespace
