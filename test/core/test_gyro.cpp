// The IMU's rotation between two stamps: the yaw rate integrated exactly along its linear interpolation,
// the yaw's difference across the +-pi seam and over whole turns, stale and missing data, the noise model.
#include "hglasm_odometry/core/gyro.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

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
  options.angle_random_walk = options.bias_sigma = options.scale_error = 0.0;
  EXPECT_GT(hglasm::gyroRotationVariance(options, 1.0, 1.0, 0.0), 0.0) << "stays invertible";
  EXPECT_TRUE(
      std::isfinite(hglasm::gyroRotationVariance(GyroOptions(), std::numeric_limits<double>::quiet_NaN(),
                                                 -1.0, std::numeric_limits<double>::quiet_NaN())));
}

/// Steps of 0.1 s (from *stamp on) with a gyro of constant `bias`, noise-free scans and a robot turning
/// `rotation` per step: the prediction is what the estimator's current bias makes of the gyro.
double learnBias(hglasm::GyroBiasEstimator* estimator, double bias, int steps, double* stamp,
                 double rotation = 0.0) {
  for (int i = 0; i < steps; ++i) {
    *stamp += 0.1;
    const double predicted = rotation + (bias - estimator->bias()) * 0.1;
    estimator->update(predicted, rotation, 0.002 * 0.002, 0.1, *stamp);
  }
  return estimator->bias();
}

TEST(GyroBiasEstimator, StartsUnknownAndLearnsAConstantBias) {
  GyroOptions options;
  hglasm::GyroBiasEstimator estimator(options);
  EXPECT_EQ(estimator.bias(), 0.0);
  EXPECT_EQ(estimator.variance(), options.bias_sigma * options.bias_sigma);
  double stamp = 0.0;
  // Each 0.1 s step sees 0.4 mrad of bias under 2 mrad of scan noise: the prior weighs as much as 18
  // steps, so after 300 the estimate has 300 / 318 of the bias.
  EXPECT_NEAR(learnBias(&estimator, 0.004, 300, &stamp), 0.004 * 300.0 / 318.0, 5e-5) << "30 s standing";
  EXPECT_LT(estimator.variance(), 0.1 * options.bias_sigma * options.bias_sigma) << "and knows it";
  EXPECT_NEAR(learnBias(&estimator, 0.004, 300, &stamp, 0.3), 0.004, 2e-4) << "30 s more, turning";
}

TEST(GyroBiasEstimator, ABiasFarOutsideThePriorIsLearnedWithinSeconds) {
  // 0.05 rad/s is ten standard deviations of the default prior.
  hglasm::GyroBiasEstimator estimator;
  double stamp = 0.0;
  EXPECT_NEAR(learnBias(&estimator, 0.05, 30, &stamp), 0.05, 2.5e-3) << "3 s";
}

TEST(GyroBiasEstimator, AChangedBiasIsFollowed) {
  hglasm::GyroBiasEstimator estimator;
  double stamp = 0.0;
  learnBias(&estimator, 0.0, 300, &stamp);
  ASSERT_LT(std::sqrt(estimator.variance()), 0.002) << "converged";
  // 0.05 rad/s is 2.4 sigma of one step's difference: the steps' running mean shows the drift.
  EXPECT_NEAR(learnBias(&estimator, 0.05, 20, &stamp), 0.05, 5e-3) << "2 s after a jump to 0.05 rad/s";
  EXPECT_NEAR(learnBias(&estimator, -0.1, 20, &stamp), -0.1, 1e-2) << "2 s after a jump to -0.1 rad/s";
}

TEST(GyroBiasEstimator, TheBiasWandersOverTheWholeTimeSinceTheLastStep) {
  GyroOptions options;
  options.bias_random_walk = 0.01;
  hglasm::GyroBiasEstimator estimator(options), gap(options);
  double stamp = 0.0, gap_stamp = 0.0;
  learnBias(&estimator, 0.0, 100, &stamp);
  learnBias(&gap, 0.0, 100, &gap_stamp);
  gap_stamp += 100.0;  // 100 s without a usable step (the IMU stale, no matches)
  learnBias(&estimator, 0.0, 1, &stamp);
  learnBias(&gap, 0.0, 1, &gap_stamp);
  EXPECT_GT(gap.variance(), 5.0 * estimator.variance());
}

TEST(GyroBiasEstimator, OneBadMatchMovesTheLearnedBiasLittle) {
  hglasm::GyroBiasEstimator estimator;
  double stamp = 0.0;
  learnBias(&estimator, 0.0, 300, &stamp);
  stamp += 0.1;
  estimator.update(0.0, 0.5, 0.002 * 0.002, 0.1, stamp);  // the scans claim half a radian the gyro never saw
  EXPECT_LT(std::abs(estimator.bias()), 0.003);
  EXPECT_NEAR(learnBias(&estimator, 0.0, 20, &stamp), 0.0, 0.003) << "and the next good steps bring it back";
}

TEST(GyroBiasEstimator, NoiseAloneNeverMakesABias) {
  // 10^5 steps (almost 3 hours at 10 Hz) of zero bias with the gyro's and the scans' noise: the estimate
  // stays near zero and the drift test never fires (a firing would let the noise pull it far).
  hglasm::GyroBiasEstimator estimator;
  std::mt19937 random(1);
  std::normal_distribution<double> scan(0.0, 0.002), gyro(0.0, 0.002 * std::sqrt(0.1));
  double stamp = 0.0, worst = 0.0;
  for (int i = 0; i < 100000; ++i) {
    stamp += 0.1;
    estimator.update(-estimator.bias() * 0.1 + gyro(random), scan(random), 0.002 * 0.002, 0.1, stamp);
    worst = std::max(worst, std::abs(estimator.bias()));
  }
  EXPECT_LT(worst, 0.004);
}

TEST(GyroBiasEstimator, IgnoresInvalidStepsAndCanBeTurnedOffAndReset) {
  hglasm::GyroBiasEstimator estimator;
  EXPECT_FALSE(estimator.update(0.1, 0.0, 1e-6, 0.0, 1.0));
  EXPECT_FALSE(estimator.update(std::nan(""), 0.0, 1e-6, 0.1, 1.0));
  EXPECT_FALSE(estimator.update(0.1, 0.0, -1.0, 0.1, 1.0));
  EXPECT_FALSE(estimator.update(0.1, 0.0, 1e-6, 0.1, std::nan("")));
  EXPECT_EQ(estimator.bias(), 0.0);
  GyroOptions noiseless;
  noiseless.angle_random_walk = noiseless.bias_sigma = noiseless.scale_error = noiseless.bias_random_walk =
      0.0;
  hglasm::GyroBiasEstimator degenerate(noiseless);
  EXPECT_FALSE(degenerate.update(0.1, 0.0, 0.0, 0.1, 1.0)) << "nothing to weigh: no 0/0";
  EXPECT_TRUE(std::isfinite(degenerate.bias()));
  double stamp = 0.0;
  learnBias(&estimator, 0.004, 100, &stamp);
  estimator.reset();
  EXPECT_EQ(estimator.bias(), 0.0);
  GyroOptions off;
  off.estimate_bias = false;
  hglasm::GyroBiasEstimator fixed(off);
  EXPECT_FALSE(fixed.update(0.01, 0.0, 1e-6, 0.1, 1.0));
  EXPECT_EQ(learnBias(&fixed, 0.004, 10, &stamp), 0.0);
}

TEST(GyroBuffer, InOrientationModeTheYawGoesOnAtTheLastRateBeyondTheSamples) {
  // Turning at 3 rad/s; the samples stop at 1.0 s; the rotation to 1.09 s (within max_gap) is 3 * 0.19.
  GyroBuffer gyro(yawOptions());
  for (int i = 0; i <= 100; ++i) gyro.add(0.01 * i, std::remainder(3.0 * 0.01 * i, 2.0 * kPi));
  double angle = 0.0;
  ASSERT_TRUE(gyro.rotation(0.9, 1.09, &angle));
  EXPECT_NEAR(angle, 3.0 * 0.19, 1e-9);
  GyroBuffer late(yawOptions());
  for (int i = 10; i <= 100; ++i) late.add(0.01 * i, 3.0 * 0.01 * i);
  ASSERT_TRUE(late.rotation(0.05, 0.2, &angle)) << "before the first sample, within max_gap";
  EXPECT_NEAR(angle, 3.0 * 0.15, 1e-9);
}

TEST(GyroBuffer, ASampleFarInTheFutureDoesNotEvictTheOthers) {
  GyroBuffer gyro(rateOptions());
  for (int i = 0; i <= 100; ++i) gyro.add(0.01 * i, 1.0);
  gyro.add(1000.0, 1.0);
  double angle = 0.0;
  ASSERT_TRUE(gyro.rotation(0.5, 0.6, &angle));
  EXPECT_NEAR(angle, 0.1, 1e-12);
  EXPECT_FALSE(gyro.rotation(1.5, 1.6, &angle)) << "the gap before the future sample is not covered";
}

TEST(GyroBuffer, ForgetBeforeKeepsTheSampleThatBoundsTheNextInterval) {
  GyroBuffer gyro(rateOptions());
  for (int i = 0; i <= 100; ++i) gyro.add(0.01 * i, 1.0);
  gyro.forgetBefore(0.505);
  double angle = 0.0;
  EXPECT_TRUE(gyro.rotation(0.505, 0.6, &angle)) << "the sample at 0.50 is kept";
  EXPECT_FALSE(gyro.rotation(0.3, 0.4, &angle)) << "forgotten";
}

}  // namespace
