// What the matches teach about the sensors: the wheels' noise scales, the IMU gyro's bias and the wheels'
// time offset, each from consecutive matched scans, and what breaks the chain of comparisons.
#include "hglasm_odometry/core/sensor_learner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_util.h"

namespace {

using hglasm::MotionPrediction;
using hglasm::Pose2D;
using hglasm::PredictionSource;
using hglasm::ScanOnlyPose;
using hglasm::SensorLearner;

/// A scan alone put the base at `pose`, to a few millimetres in every direction.
ScanOnlyPose scanAt(const Pose2D& pose) {
  ScanOnlyPose scan;
  scan.pose = pose;
  scan.usable = true;
  for (int j = 0; j < 3; ++j) scan.covariance_parts[j] = Eigen::Matrix3d::Zero();
  scan.covariance_parts[0](0, 0) = scan.covariance_parts[1](1, 1) = 1e-6;
  scan.covariance_parts[2](2, 2) = 1e-7;
  return scan;
}

/// The wheels' prediction of `motion` over `dt` with the configured (unit-scale) noise of `learner`.
MotionPrediction wheels(const SensorLearner& learner, const Pose2D& motion, double dt) {
  MotionPrediction prediction;
  prediction.source = PredictionSource::kOdometry;
  prediction.dt = dt;
  prediction.motion = prediction.wheel_motion = motion;
  prediction.covariance = learner.wheelNoise().odometryCovariance(motion, dt);
  prediction.nominal_covariance = learner.wheelNoise().nominalOdometryCovariance(motion, dt);
  return prediction;
}

TEST(SensorLearner, WheelsMoreAccurateThanTheirModelLearnASmallerNoise) {
  SensorLearner learner({}, {}, {});
  EXPECT_EQ(learner.wheelNoise().scale().xy, 1.0);
  Pose2D pose;
  for (int i = 0; i < 300; ++i) {
    const Pose2D step(0.05, 0.0, 0.01);
    learner.addMatchedScan(wheels(learner, step, 0.1), 0.1 * i, scanAt(pose * step), true);
    pose = pose * step;
  }
  EXPECT_LT(learner.wheelNoise().scale().xy, 0.2) << "the wheels agreed with the scans to the millimetre";
  EXPECT_LT(learner.wheelNoise().scale().theta, 0.2);
  EXPECT_TRUE(learner.lastScanUsable());
  EXPECT_EQ(learner.learned().wheel_noise.xy, learner.wheelNoise().scale().xy);
}

TEST(SensorLearner, LeapsAndUnusableScansTeachTheWheelsNothing) {
  SensorLearner learner({}, {}, {});
  Pose2D pose;
  for (int i = 0; i < 100; ++i) {
    const Pose2D step(0.05, 0.0, 0.0);
    ScanOnlyPose scan = scanAt(pose * step);
    scan.usable = i % 2 == 0;  // every other scan is degenerate
    learner.addMatchedScan(wheels(learner, step, 0.1), 0.1 * i, scan, false);
    EXPECT_EQ(learner.lastScanUsable(), scan.usable) << i;
    pose = pose * step;
  }
  EXPECT_EQ(learner.wheelNoise().scale().xy, 1.0);
  EXPECT_EQ(learner.wheelNoise().scale().theta, 1.0);
}

/// A learner with an IMU whose rotations run `bias` rad/s fast, fed `steps` steps of `dt`; every
/// `unmatched_every`-th scan (0: none) has no match.
double learnedBias(double bias, int steps, double dt, int unmatched_every) {
  hglasm::GyroOptions imu;
  imu.bias_sigma = 0.05;
  SensorLearner learner({}, {}, imu);
  Pose2D pose;
  for (int i = 0; i < steps; ++i) {
    const Pose2D step(0.0, 0.0, 0.3 * dt);
    MotionPrediction prediction;
    prediction.source = PredictionSource::kConstantVelocity;
    prediction.dt = dt;
    prediction.rotation_from_imu = true;
    prediction.motion = Pose2D(0.0, 0.0, step.theta + bias * dt - learner.imuBias().bias() * dt);
    pose = pose * step;
    if (unmatched_every > 0 && i % unmatched_every == 0) {
      learner.addUnmatchedScan();
    } else {
      learner.addMatchedScan(prediction, dt * i, scanAt(pose), true);
    }
  }
  return learner.imuBias().bias();
}

TEST(SensorLearner, TheImuBiasIsLearnedFromConsecutiveMatchedScans) {
  EXPECT_NEAR(learnedBias(0.02, 300, 0.1, 0), 0.02, 0.002);
  EXPECT_NEAR(learnedBias(-0.01, 300, 0.1, 0), -0.01, 0.002);
  EXPECT_EQ(learnedBias(0.02, 300, 0.1, 1), 0.0) << "no two matched scans in a row: nothing to compare";
  EXPECT_NEAR(learnedBias(0.02, 600, 0.1, 2), 0.0, 1e-12) << "every other scan unmatched: no pairs either";
  EXPECT_NEAR(learnedBias(0.02, 300, 0.1, 3), 0.02, 0.003) << "pairs between the gaps still teach it";
}

TEST(SensorLearner, AFixedTimeOffsetNeverChanges) {
  hglasm::SensorLearningOptions options;
  options.odometry_time_offset.estimate = false;
  options.odometry_time_offset.offset = 0.2;
  SensorLearner learner(options, {}, {});
  hglasm::OdometryBuffer buffer;
  for (int i = 0; i <= 500; ++i) buffer.add(0.02 * i, Pose2D(0.0, 0.0, 0.5 * std::sin(0.02 * i)));
  for (int i = 0; i < 80; ++i) {
    learner.addMatchedScan(MotionPrediction(), 0.1 * i, scanAt(Pose2D(0.0, 0.0, 0.5 * std::sin(0.1 * i))),
                           true);
    EXPECT_FALSE(learner.learnTimeOffset(0.1 * i, buffer));
  }
  EXPECT_EQ(learner.odometryTimeOffset().offset(), 0.2);
}

TEST(SensorLearner, ALateWheelClockIsFoundAndTheWheelsLearningForgotten) {
  // The wheels stamp their pose 0.3 s late; the robot swings its heading back and forth.
  constexpr double kLate = 0.3;
  const auto heading = [](double t) { return 0.6 * std::sin(1.3 * t) + 0.2 * std::sin(3.1 * t); };
  SensorLearner learner({}, {}, {});
  hglasm::OdometryBuffer buffer(1e6);
  for (int i = 0; i <= 3000; ++i) buffer.add(0.02 * i + kLate, Pose2D(0.0, 0.0, heading(0.02 * i)));
  bool changed = false;
  double scale_before_change = 1.0;
  for (int i = 1; i < 500 && !changed; ++i) {
    const double t = 0.1 * i;
    // The wheels' step as read at the scans' stamps (0.3 s off), against where the scans put the base.
    const Pose2D step(0.0, 0.0, heading(t - kLate) - heading(t - 0.1 - kLate));
    learner.addMatchedScan(wheels(learner, step, 0.1), t - 0.1, scanAt(Pose2D(0.0, 0.0, heading(t))), true);
    scale_before_change = learner.wheelNoise().scale().theta;
    changed = learner.learnTimeOffset(t, buffer);
  }
  ASSERT_TRUE(changed);
  EXPECT_NEAR(learner.odometryTimeOffset().offset(), kLate, 0.03);
  EXPECT_GT(scale_before_change, 1.5) << "the offset looked like heading noise";
  EXPECT_EQ(learner.wheelNoise().scale().theta, 1.0) << "forgotten";
}

}  // namespace
