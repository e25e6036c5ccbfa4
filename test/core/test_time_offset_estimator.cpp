// The wheels' time offset learned from the matches: synthetic wheels that lag (or lead) a known turning
// motion by a known offset, sampled at 50 Hz, against scan poses at 10 Hz.
#include "hglasm_odometry/core/time_offset_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test_util.h"

namespace {

using hglasm::OdometryBuffer;
using hglasm::Pose2D;
using hglasm::TimeOffsetEstimator;
using hglasm::TimeOffsetOptions;

/// A robot driving at 0.4 m/s whose turn rate changes every few seconds (as a robot's does).
Pose2D wiggle(double t) {
  const double heading = 0.6 * std::sin(0.7 * t) + 0.3 * std::sin(1.9 * t);
  return hglasm_test::rawPose(0.4 * t, 0.0, hglasm_test::angleDiff(heading, 0.0));
}

/// Feeds `seconds` of the robot: wheels stamped `lag` s late (their pose of t carries t + lag) with a
/// 3 % turn scale error, and scan poses with 2 mrad of heading noise (a seeded generator).
/// With `jumps`, the wheels' frame turns by 1 rad every 7 s (and back 3 s later): a driver's glitches.
double learn(TimeOffsetEstimator* estimator, double lag, double seconds, bool turning = true,
             bool jumps = false) {
  OdometryBuffer wheels(60.0);
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  const auto path = [turning](double t) {
    return turning ? wiggle(t) : hglasm_test::rawPose(0.4 * t, 0.0, 0.0);
  };
  double next_wheel = 0.0;
  for (double t = 0.0; t <= seconds; t += 0.1) {
    for (; next_wheel <= t + 0.1; next_wheel += 0.02) {
      const Pose2D truth = path(next_wheel);
      const double glitch = jumps && std::fmod(next_wheel, 7.0) >= 4.0 ? 1.0 : 0.0;
      wheels.add(next_wheel + lag, Pose2D(truth.x, truth.y, 1.03 * truth.theta + glitch));
    }
    const Pose2D seen = path(t);
    estimator->addScanPose(t, Pose2D(seen.x, seen.y, seen.theta + noise(random)));
    estimator->update(wheels);
  }
  return estimator->offset();
}

TEST(TimeOffsetEstimator, FindsWheelsThatLagOrLead) {
  for (const double lag : {0.3, 0.6, -0.2, 0.9}) {
    SCOPED_TRACE("lag " + std::to_string(lag));
    TimeOffsetEstimator estimator;
    EXPECT_EQ(estimator.offset(), 0.0) << "none until the evidence suffices";
    EXPECT_NEAR(learn(&estimator, lag, 120.0), lag, 0.01);
    EXPECT_NEAR(estimator.estimate(), lag, 0.01);
    EXPECT_GT(estimator.windows(), 50.0);
  }
}

TEST(TimeOffsetEstimator, AnOffsetBelowTheDeadBandIsNone) {
  TimeOffsetEstimator estimator;
  learn(&estimator, 0.03, 120.0);
  EXPECT_NEAR(estimator.estimate(), 0.03, 0.01) << "seen";
  EXPECT_EQ(estimator.offset(), 0.0) << "but not used: under kMinOffset";
}

TEST(TimeOffsetEstimator, WithoutTurnsThereIsNoEvidence) {
  TimeOffsetEstimator estimator;
  EXPECT_EQ(learn(&estimator, 0.4, 60.0, false), 0.0);
}

TEST(TimeOffsetEstimator, JumpsOfTheWheelsFrameAreNoEvidence) {
  // Whichever shift moves a jump out of a window fits it better: without the jump test a wrong offset.
  TimeOffsetEstimator estimator;
  EXPECT_EQ(learn(&estimator, 0.0, 120.0, true, true), 0.0);
  EXPECT_NEAR(estimator.estimate(), 0.0, 0.02);
  EXPECT_GT(estimator.windows(), 5.0) << "the windows between the jumps still count";
  TimeOffsetEstimator lagging;
  EXPECT_NEAR(learn(&lagging, 0.3, 120.0, true, true), 0.3, 0.02);
}

TEST(TimeOffsetEstimator, AFixedOffsetNeverChanges) {
  TimeOffsetOptions fixed;
  fixed.estimate = false;
  fixed.offset = 0.25;
  TimeOffsetEstimator estimator(fixed);
  EXPECT_EQ(learn(&estimator, 0.6, 60.0), 0.25);
  EXPECT_EQ(estimator.windows(), 0.0);
}

TEST(TimeOffsetEstimator, ALongGapStartsTheNextWindowAfresh) {
  // A pause of a minute (no matches) between two scan poses is not a window: its turn says nothing of the
  // wheels' timing.
  TimeOffsetEstimator estimator;
  OdometryBuffer wheels(300.0);
  for (double t = 0.0; t <= 70.0; t += 0.02) wheels.add(t, wiggle(t));
  estimator.addScanPose(0.0, wiggle(0.0));
  estimator.addScanPose(60.0, wiggle(60.0));
  estimator.update(wheels);
  EXPECT_EQ(estimator.windows(), 0.0);
  estimator.addScanPose(61.0, wiggle(61.0));
  estimator.update(wheels);
  EXPECT_EQ(estimator.windows(), 1.0);
}

}  // namespace
