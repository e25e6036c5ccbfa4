// Learning both noises from the innovations between the scans' and the wheels' motion: simulated chains
// with known wheel and scan noise scales, which the learner must find.
#include "hglasm_odometry/core/noise_learner.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

namespace {

using hglasm::MotionNoiseModel;
using hglasm::NoiseLearner;
using hglasm::NoiseLearnerOptions;
using hglasm::NoiseSample;
using hglasm::Pose2D;
using hglasm::ScanNoiseScale;

/// A chain of scans along a gently turning path: the wheels' motion carries a random walk of `wheel_scale`
/// times the nominal model, each scan's pose white noise of `scan_scale` times the stated covariance along
/// the directions of `information` (odometry-frame coordinates).
class SimulatedChain {
 public:
  SimulatedChain(double wheel_xy, double wheel_theta, const ScanNoiseScale& scan_scale,
                 const Eigen::Matrix3d& information, std::uint64_t seed)
      : wheel_xy_(wheel_xy), wheel_theta_(wheel_theta), rng_(seed) {
    parts_ = hglasm::covarianceByDirection(hglasm::informationDirections(information), 1e4);
    Eigen::Matrix3d scan_covariance = Eigen::Matrix3d::Zero();
    for (int j = 0; j < 3; ++j) scan_covariance += scan_scale[j] * parts_[j];
    scan_root_ = scan_covariance.llt().matrixL();
  }

  NoiseSample next() {
    const Pose2D step(0.1, 0.0, 0.03 * std::sin(0.05 * count_++));
    NoiseSample sample;
    const Eigen::Matrix3d nominal = model_.nominalOdometryCovariance(step, 0.2);
    sample.wheel_xy = nominal;
    sample.wheel_xy.row(2).setZero();
    sample.wheel_xy.col(2).setZero();
    sample.wheel_theta(2, 2) = nominal(2, 2);
    sample.wheel_motion = Pose2D(step.x + normal() * std::sqrt(wheel_xy_ * nominal(0, 0)),
                                 step.y + normal() * std::sqrt(wheel_xy_ * nominal(1, 1)),
                                 step.theta + normal() * std::sqrt(wheel_theta_ * nominal(2, 2)));
    truth_ = truth_ * step;
    const Eigen::Vector3d error = scan_root_ * Eigen::Vector3d(normal(), normal(), normal());
    sample.scan_pose = Pose2D(truth_.x + error.x(), truth_.y + error.y(), truth_.theta + error.z());
    sample.scan_covariance = parts_;
    return sample;
  }

 private:
  double normal() { return normal_(rng_); }

  double wheel_xy_, wheel_theta_;
  std::array<Eigen::Matrix3d, 3> parts_;
  Eigen::Matrix3d scan_root_;
  MotionNoiseModel model_;
  Pose2D truth_;
  int count_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
};

/// A scan that knows heading best, then across the robot's track, then (least) along it; each about as
/// precise as the wheels over a step, so that the data can tell every one of its scales.
Eigen::Matrix3d corridorLikeInformation() {
  return Eigen::Vector3d(1.0 / (0.03 * 0.03), 1.0 / (0.01 * 0.01), 1.0 / (0.005 * 0.005)).asDiagonal();
}

NoiseLearnerOptions learningBoth() {
  NoiseLearnerOptions options;
  options.learn_scan = true;
  return options;
}

NoiseLearner learnFrom(SimulatedChain* chain, int count,
                       const NoiseLearnerOptions& options = learningBoth()) {
  NoiseLearner learner(options);
  for (int i = 0; i < count; ++i) learner.add(chain->next());
  return learner;
}

TEST(NoiseLearner, TellsTheWheelsNoiseFromTheScansByHowEachGrowsWithTheSpan) {
  // Good wheels and a scan that overstates its information fourfold; then bad wheels and a scan that
  // states it as it is. Both are found, though the innovations alone only ever show their sum.
  NoiseLearnerOptions options;
  options.learn_scan = true;
  options.half_life = 2000.0;
  SimulatedChain good_wheels(0.05, 0.1, ScanNoiseScale(4.0, 4.0, 4.0), corridorLikeInformation(), 1);
  const NoiseLearner first = learnFrom(&good_wheels, 6000, options);
  EXPECT_NEAR(first.wheelScale().xy, 0.05, 0.02);
  EXPECT_NEAR(first.wheelScale().theta, 0.1, 0.04);
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(first.scanScale()[j], 4.0, 1.0) << "direction " << j;

  // Where the wheels' noise dwarfs the scan's, the scan's share is measured less well.
  SimulatedChain bad_wheels(10.0, 5.0, ScanNoiseScale(1.0, 1.0, 1.0), corridorLikeInformation(), 2);
  const NoiseLearner second = learnFrom(&bad_wheels, 6000, options);
  EXPECT_NEAR(second.wheelScale().xy, 10.0, 2.5);
  EXPECT_NEAR(second.wheelScale().theta, 5.0, 1.5);
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(second.scanScale()[j], 1.0, 0.6) << "direction " << j;
}

TEST(NoiseLearner, LearnsTheScansNoiseDirectionByDirection) {
  // Only the scan's weakest direction (along the track) is overstated, tenfold: only its scale grows.
  NoiseLearnerOptions options;
  options.learn_scan = true;
  options.half_life = 2000.0;
  SimulatedChain chain(1.0, 1.0, ScanNoiseScale(10.0, 1.0, 1.0), corridorLikeInformation(), 3);
  const NoiseLearner directional = learnFrom(&chain, 6000, options);
  EXPECT_NEAR(directional.scanScale()[0], 10.0, 3.0);
  EXPECT_NEAR(directional.scanScale()[1], 1.0, 0.4);
  EXPECT_NEAR(directional.scanScale()[2], 1.0, 0.4);
  // One scale for every direction cannot: it lands between, overstating one and understating the others.
  options.directional = false;
  SimulatedChain again(1.0, 1.0, ScanNoiseScale(10.0, 1.0, 1.0), corridorLikeInformation(), 3);
  const NoiseLearner single = learnFrom(&again, 6000, options);
  EXPECT_EQ(single.scanScale()[0], single.scanScale()[2]);
  EXPECT_GT(single.scanScale()[0], 1.5);
  EXPECT_LT(single.scanScale()[0], 8.0);
}

TEST(NoiseLearner, OneWildInnovationDoesNotTeachThatEitherWitnessIsBad) {
  SimulatedChain chain(1.0, 1.0, ScanNoiseScale(1.0, 1.0, 1.0), corridorLikeInformation(), 4);
  NoiseLearner learner = learnFrom(&chain, 1000);
  const double wheels_before = learner.wheelScale().xy;
  const double scan_before = learner.scanScale()[0];
  NoiseSample wild = chain.next();
  wild.scan_pose.x += 5.0;  // a door swinging past: 5 m
  learner.add(wild);
  EXPECT_LT(learner.wheelScale().xy, 1.3 * wheels_before);
  EXPECT_LT(learner.scanScale()[0], 1.3 * scan_before);
}

TEST(NoiseLearner, NeverComparesAcrossABreakAndCanBeTurnedOffOrReset) {
  // Across a break (a leap) the wheels' motion since the last sample is unknown: a jump of 3 m there
  // teaches nothing.
  SimulatedChain chain(1.0, 1.0, ScanNoiseScale(1.0, 1.0, 1.0), corridorLikeInformation(), 5);
  NoiseLearner learner = learnFrom(&chain, 500);
  const NoiseLearner::Vector before(learner.wheelScale().xy, learner.wheelScale().theta,
                                    learner.scanScale()[0], learner.scanScale()[1], learner.scanScale()[2]);
  learner.breakChain();
  NoiseSample jumped = chain.next();
  jumped.scan_pose.x += 3.0;
  learner.add(jumped);
  EXPECT_EQ(learner.wheelScale().xy, before[0]) << "a single sample after a break compares with nothing";

  NoiseLearnerOptions off;
  off.learn_wheels = off.learn_scan = false;
  SimulatedChain bad(10.0, 10.0, ScanNoiseScale(10.0, 10.0, 10.0), corridorLikeInformation(), 6);
  const NoiseLearner fixed = learnFrom(&bad, 500, off);
  EXPECT_EQ(fixed.wheelScale().xy, 1.0);
  EXPECT_EQ(fixed.scanScale()[0], 1.0);

  SimulatedChain bad_again(10.0, 10.0, ScanNoiseScale(1.0, 1.0, 1.0), corridorLikeInformation(), 7);
  NoiseLearner learned = learnFrom(&bad_again, 1000);
  EXPECT_GT(learned.wheelScale().xy, 3.0);
  learned.reset();
  EXPECT_EQ(learned.wheelScale().xy, 1.0);
  EXPECT_EQ(learned.scanEvidenceScale(), 1.0);
  // Non-finite samples change nothing.
  NoiseSample broken = bad_again.next();
  broken.scan_pose.x = std::nan("");
  learned.add(broken);
  learned.add(broken);
  EXPECT_NEAR(learned.wheelScale().xy, 1.0, 1e-12);
}

}  // namespace
