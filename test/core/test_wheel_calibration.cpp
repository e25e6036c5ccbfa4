// The wheels' systematic errors learned from the scans' motion, and removed from the wheels' motion.
#include "hglasm_odometry/core/wheel_calibration.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>

namespace {

using hglasm::Pose2D;
using hglasm::WheelCalibration;
using hglasm::WheelCalibrationOptions;

/// Learning all three errors, each with a prior of how miscalibrated wheels may be.
WheelCalibrationOptions allThree() {
  WheelCalibrationOptions options;
  options.learn = true;
  options.turn_scale = 0.1;
  options.heading_per_metre = 0.02;
  options.distance_scale = 0.05;
  return options;
}

/// Wheels that count turns `turn_scale` short (true turn = wheels' * (1 + turn_scale)), drift by
/// `heading_per_metre`, and count distances `distance_scale` short; the scans see the true motion with
/// noise. Returns the learned calibration.
WheelCalibration learnFrom(double turn_scale, double heading_per_metre, double distance_scale, int steps,
                           std::uint64_t seed, WheelCalibrationOptions options = allThree()) {
  WheelCalibration calibration(options);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const double heading_sigma = 0.002, distance_sigma = 0.005;
  for (int i = 0; i < steps; ++i) {
    const double distance = 0.2 + 0.1 * std::sin(0.03 * i);
    const double turn = 0.3 * std::sin(0.05 * i);
    const Pose2D truth(distance * std::cos(0.5 * turn), distance * std::sin(0.5 * turn), turn);
    const double wheel_distance = distance / (1.0 + distance_scale);
    const double wheel_turn = (turn - heading_per_metre * wheel_distance) / (1.0 + turn_scale);
    const Pose2D wheels(wheel_distance * std::cos(0.5 * wheel_turn),
                        wheel_distance * std::sin(0.5 * wheel_turn), wheel_turn);
    const Pose2D scans(truth.x + distance_sigma * normal(rng), truth.y + distance_sigma * normal(rng),
                       truth.theta + heading_sigma * normal(rng));
    calibration.learn(wheels, scans, heading_sigma * heading_sigma, distance_sigma * distance_sigma);
  }
  return calibration;
}

TEST(WheelCalibration, LearnsATurnScaleAHeadingDriftAndADistanceScale) {
  const WheelCalibration calibration = learnFrom(0.05, 0.01, 0.03, 5000, 1);
  EXPECT_NEAR(calibration.turnScale(), 0.05, 0.005);
  EXPECT_NEAR(calibration.headingPerMetre(), 0.01, 0.001);
  EXPECT_NEAR(calibration.distanceScale(), 0.03, 0.003);
  // Corrected, a wheel step is the true one.
  const double wheel_distance = 0.5 / 1.03, wheel_turn = (0.4 - 0.01 * wheel_distance) / 1.05;
  const Pose2D corrected = calibration.correct(Pose2D(
      wheel_distance * std::cos(0.5 * wheel_turn), wheel_distance * std::sin(0.5 * wheel_turn), wheel_turn));
  EXPECT_NEAR(corrected.theta, 0.4, 0.003);
  EXPECT_NEAR(corrected.translationNorm(), 0.5, 0.003);
  EXPECT_NEAR(std::atan2(corrected.y, corrected.x), 0.2, 0.003) << "the chord of the corrected arc";
}

TEST(WheelCalibration, CalibratedWheelsLearnNothingAndNothingIsCorrected) {
  const WheelCalibration calibration = learnFrom(0.0, 0.0, 0.0, 5000, 2);
  EXPECT_NEAR(calibration.turnScale(), 0.0, 0.003);
  EXPECT_NEAR(calibration.headingPerMetre(), 0.0, 0.001);
  EXPECT_NEAR(calibration.distanceScale(), 0.0, 0.003);
  const WheelCalibration untouched;
  const Pose2D step(0.31, -0.02, 0.17);
  const Pose2D same = untouched.correct(step);
  EXPECT_EQ(same.x, step.x);
  EXPECT_EQ(same.y, step.y);
  EXPECT_EQ(same.theta, step.theta);
}

TEST(WheelCalibration, TheDefaultLearnsTheTurnScaleAlone) {
  // Wheels with all three errors: the default takes the drift per metre and the distance scale as none (the
  // scans confound them with their own slow errors) and learns the turn scale, which every turn shows.
  const WheelCalibration calibration = learnFrom(0.05, 0.01, 0.03, 5000, 4, WheelCalibrationOptions());
  EXPECT_NEAR(calibration.headingPerMetre(), 0.0, 1e-9);
  EXPECT_EQ(calibration.distanceScale(), 0.0);
  EXPECT_NEAR(calibration.turnScale(), 0.05, 0.01);
  const Pose2D corrected = calibration.correct(Pose2D(1.0, 0.0, 0.4 / 1.05));
  EXPECT_NEAR(corrected.theta, 0.4, 0.004);
  EXPECT_NEAR(corrected.translationNorm(), 1.0, 1e-12) << "the distance is the wheels'";
}

TEST(WheelCalibration, AStepItCannotExplainIsLeftOutAndLearningCanBeOff) {
  WheelCalibration calibration = learnFrom(0.0, 0.0, 0.0, 2000, 3);
  const double before = calibration.turnScale();
  // A slip: the scans saw a quarter turn the wheels did not count.
  calibration.learn(Pose2D(0.2, 0.0, 0.1), Pose2D(0.2, 0.0, 0.1 + M_PI / 2), 1e-6, 1e-4);
  EXPECT_EQ(calibration.turnScale(), before);
  WheelCalibrationOptions off = allThree();
  off.learn = false;
  WheelCalibration fixed(off);
  for (int i = 0; i < 100; ++i) fixed.learn(Pose2D(0.2, 0.0, 0.1), Pose2D(0.25, 0.0, 0.2), 1e-6, 1e-4);
  EXPECT_EQ(fixed.turnScale(), 0.0);
  EXPECT_EQ(fixed.distanceScale(), 0.0);
  // Non-finite input changes nothing; an IMU's step (no heading variance) teaches the distance only.
  calibration.learn(Pose2D(std::nan(""), 0.0, 0.0), Pose2D(), 1e-6, 1e-4);
  EXPECT_TRUE(std::isfinite(calibration.turnScale()));
  calibration.reset();
  EXPECT_EQ(calibration.turnScale(), 0.0);
}

/// Steps of a robot driving arcs whose laser truly sits at `truth_mount` while tf states `stated`: the
/// laser's own motion (truth_mount^-1 W truth_mount, with `noise` m of translation noise) against the
/// wheels' exact motion W. Returns the learned calibration.
WheelCalibrationOptions learningTheMount() {
  WheelCalibrationOptions options;
  options.laser_offset = 0.1;
  return options;
}

WheelCalibration learnMountFrom(const Pose2D& truth_mount, const Pose2D& stated, double noise, int steps,
                                double max_turn, WheelCalibrationOptions options = learningTheMount()) {
  WheelCalibration calibration(options);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * (2.0 * noise * noise);
  for (int i = 0; i < steps; ++i) {
    const double distance = 0.1 + 0.05 * std::sin(0.03 * i);
    const double turn = max_turn * std::sin(0.05 * i);
    const Pose2D wheels(distance * std::cos(0.5 * turn), distance * std::sin(0.5 * turn), turn);
    Pose2D laser = truth_mount.inverse() * wheels * truth_mount;
    laser.x += noise * normal(rng);
    laser.y += noise * normal(rng);
    calibration.learnLaserOffset(wheels, laser, stated, covariance);
  }
  return calibration;
}

TEST(WheelCalibration, LearnsWhereTheLaserSitsFromTheTurns) {
  // A laser 8 cm ahead of and 3 cm right of where tf (which has its yaw right) puts it; 5 mm of noise.
  const Pose2D stated(0.2, 0.1, 0.3);
  const Pose2D truth(0.28, 0.07, 0.3);
  const WheelCalibration calibration = learnMountFrom(truth, stated, 0.005, 3000, 0.2);
  EXPECT_NEAR(calibration.laserOffset().x(), 0.08, 0.003);
  EXPECT_NEAR(calibration.laserOffset().y(), -0.03, 0.003);
  // With the mount right there is nothing to learn.
  const WheelCalibration right = learnMountFrom(truth, truth, 0.005, 3000, 0.2);
  EXPECT_NEAR(right.laserOffset().norm(), 0.0, 0.003);
}

TEST(WheelCalibration, WithoutTurnsOrWhenOffTheMountIsLeftAsStated) {
  // Driving straight, a lever arm moves nothing: the prior keeps the offset at zero.
  const Pose2D stated, truth(0.1, 0.05, 0.0);
  EXPECT_NEAR(learnMountFrom(truth, stated, 0.005, 2000, 0.0).laserOffset().norm(), 0.0, 1e-9);
  EXPECT_EQ(learnMountFrom(truth, stated, 0.005, 2000, 0.2, WheelCalibrationOptions()).laserOffset().norm(),
            0.0)
      << "by default the mount is exact";
  WheelCalibrationOptions off = learningTheMount();
  off.learn = false;
  EXPECT_EQ(learnMountFrom(truth, stated, 0.005, 2000, 0.2, off).laserOffset().norm(), 0.0);
  // A step it cannot explain (a slip of 0.3 m sideways in a turn) is left out; reset() forgets.
  WheelCalibration calibration = learnMountFrom(truth, stated, 0.005, 2000, 0.2);
  const Eigen::Vector2d before = calibration.laserOffset();
  EXPECT_NEAR(before.x(), 0.1, 0.005);
  calibration.learnLaserOffset(Pose2D(0.1, 0.0, 0.2), Pose2D(0.1, 0.3, 0.2), stated,
                               Eigen::Matrix2d::Identity() * 5e-5);
  EXPECT_EQ(calibration.laserOffset(), before);
  calibration.learnLaserOffset(Pose2D(0.1, 0.0, 0.2), Pose2D(0.1, 0.0, 0.2), stated,
                               Eigen::Matrix2d::Identity() * std::nan(""));
  EXPECT_EQ(calibration.laserOffset(), before) << "a non-finite covariance teaches nothing";
  calibration.reset();
  EXPECT_EQ(calibration.laserOffset().norm(), 0.0);
}

}  // namespace
