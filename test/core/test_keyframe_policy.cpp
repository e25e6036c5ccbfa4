// Which scans become keyframes: moved or turned past the thresholds since the newest keyframe (measured
// between the two base poses, angles wrapped), a failed or poor match (another scanner geometry is no
// reason); which stay out (leaps, taken or waiting, the scans after a leap until one fits as usual, and with
// keyframe/max_turn_rate due scans that turn fast while they fit) and which restart the map (two unexplained
// in a row).
#include "hglasm_odometry/core/keyframe_policy.h"

#include <gtest/gtest.h>

#include "test_util.h"

namespace {

using hglasm::KeyframePolicy;
using hglasm::Pose2D;
using hglasm_test::kPi;

constexpr double kDistance = 0.5;    // m
constexpr double kAngle = 0.25;      // rad
constexpr double kMinFitness = 0.6;  // fitness ratio

/// A policy whose newest keyframe was taken with the base at `keyframe` by a 360-beam scanner.
KeyframePolicy policyAt(const Pose2D& keyframe) {
  hglasm::KeyframeOptions options;
  options.distance = kDistance;
  options.angle = kAngle;
  options.min_fitness = kMinFitness;
  KeyframePolicy policy(options);
  policy.keyframeAdded(keyframe);
  return policy;
}

/// Whether a well matched scan (fitness ratio 1) with the base at `pose` becomes a keyframe.
bool movedEnough(const KeyframePolicy& policy, const Pose2D& pose) {
  return policy.wantsKeyframe(pose, true, false, 1.0);
}

TEST(KeyframePolicy, DistanceFromTheKeyframeInAnyDirection) {
  const KeyframePolicy policy = policyAt(Pose2D(2.0, -1.0, 0.0));
  EXPECT_FALSE(movedEnough(policy, Pose2D(2.0, -1.0, 0.0)));
  EXPECT_FALSE(movedEnough(policy, Pose2D(2.5, -1.0, 0.0)));  // exactly the threshold: not past it
  EXPECT_TRUE(movedEnough(policy, Pose2D(2.5625, -1.0, 0.0)));
  EXPECT_FALSE(movedEnough(policy, Pose2D(2.0, -1.4375, 0.0)));
  EXPECT_TRUE(movedEnough(policy, Pose2D(2.0, -1.5625, 0.0)));
  // Diagonally: 0.45 m, then 0.54 m.
  EXPECT_FALSE(movedEnough(policy, Pose2D(1.75, -0.625, 0.0)));
  EXPECT_TRUE(movedEnough(policy, Pose2D(1.6875, -0.5625, 0.0)));
}

TEST(KeyframePolicy, HeadingChangeWrapsAroundPi) {
  const KeyframePolicy policy = policyAt(Pose2D(0.0, 0.0, 3.0));
  EXPECT_FALSE(movedEnough(policy, Pose2D(0.0, 0.0, 3.125)));
  EXPECT_TRUE(movedEnough(policy, Pose2D(0.0, 0.0, 2.6875)));
  // 3.0 to -3.0 rad is a turn of 2 pi - 6 = 0.283 rad, past 0.25; 3.0 to -3.1 is 0.183 rad, not.
  EXPECT_TRUE(movedEnough(policy, Pose2D(0.0, 0.0, -3.0)));
  EXPECT_FALSE(movedEnough(policy, Pose2D(0.0, 0.0, -3.1)));
  EXPECT_FALSE(movedEnough(policy, Pose2D(0.0, 0.0, 2 * kPi - 3.2)));
}

TEST(KeyframePolicy, FailedOrPoorMatch) {
  const Pose2D here(1.0, 1.0, 0.5);
  const KeyframePolicy policy = policyAt(here);
  EXPECT_FALSE(policy.wantsKeyframe(here, true, false, kMinFitness));
  EXPECT_TRUE(policy.wantsKeyframe(here, true, false, 0.59));
  EXPECT_TRUE(policy.wantsKeyframe(here, false, true, 0.0));
  // Not matched (the prediction was integrated, e.g. a scan too short): its fit says nothing.
  EXPECT_FALSE(policy.wantsKeyframe(here, false, false, 0.0));
}

TEST(KeyframePolicy, KeyframeAddedMovesTheReference) {
  KeyframePolicy policy = policyAt(Pose2D(0.0, 0.0, 0.0));
  const Pose2D far(3.0, 0.0, 1.0);
  EXPECT_TRUE(movedEnough(policy, far));
  policy.keyframeAdded(far);
  EXPECT_FALSE(movedEnough(policy, far));
  EXPECT_TRUE(movedEnough(policy, Pose2D(0.0, 0.0, 0.0)));
  EXPECT_EQ(policy.keyframes(), 2) << "policyAt() added the first";
}

/// A scan at `pose`, usable, matched, fitting well.
hglasm::KeyframeCandidate scanAt(const Pose2D& pose) {
  hglasm::KeyframeCandidate scan;
  scan.pose = pose;
  scan.usable = true;
  scan.matched = true;
  scan.fitness_ratio = 0.9;
  return scan;
}

TEST(KeyframePolicy, DecideAddsWhatWantsKeyframeWantsAndFillsAnEmptyMap) {
  using hglasm::KeyframeAction;
  KeyframePolicy policy = policyAt(Pose2D());
  EXPECT_EQ(policy.decide(scanAt(Pose2D(0.1, 0.0, 0.0)), false), KeyframeAction::kNone);
  EXPECT_EQ(policy.decide(scanAt(Pose2D(0.6, 0.0, 0.0)), false), KeyframeAction::kAdd);
  EXPECT_EQ(policy.decide(scanAt(Pose2D(0.1, 0.0, 0.0)), true), KeyframeAction::kAdd) << "an empty map";
  hglasm::KeyframeCandidate unusable = scanAt(Pose2D(0.6, 0.0, 0.0));
  unusable.usable = false;
  EXPECT_EQ(policy.decide(unusable, true), KeyframeAction::kNone) << "no points to hold";
  hglasm::KeyframeCandidate leapt = scanAt(Pose2D(0.6, 0.0, 0.0));
  leapt.leapt = true;
  EXPECT_EQ(policy.decide(leapt, false), KeyframeAction::kNone)
      << "a keyframe would hold the map to the leap";
}

TEST(KeyframePolicy, OneUnexplainedScanStaysOutTheSecondRestartsTheMap) {
  using hglasm::KeyframeAction;
  KeyframePolicy policy = policyAt(Pose2D());
  hglasm::KeyframeCandidate unexplained = scanAt(Pose2D(0.05, 0.0, 0.0));
  unexplained.match_failed = true;
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone) << "someone in front of the laser";
  EXPECT_EQ(policy.decide(scanAt(Pose2D(0.05, 0.0, 0.0)), false), KeyframeAction::kNone) << "the map holds";
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone) << "one in a row again";
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kRestartMap) << "two in a row";
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone) << "the count starts afresh";
  policy.restart();
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone) << "a restart forgets the first";
  EXPECT_EQ(policy.decide(unexplained, true), KeyframeAction::kAdd) << "an empty map explains nothing";
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone) << "and counts afresh";
}

TEST(KeyframePolicy, AWaitingLeapStaysOutAndCountsAsUnexplainedWhenItFitsNowhereAsUsual) {
  using hglasm::KeyframeAction;
  KeyframePolicy policy = policyAt(Pose2D());
  hglasm::KeyframeCandidate waiting = scanAt(Pose2D(0.6, 0.0, 0.0));  // far enough for a keyframe
  waiting.leap_deferred = true;
  EXPECT_EQ(policy.decide(waiting, false), KeyframeAction::kNone) << "it fit near the prediction: it waits";
  EXPECT_EQ(policy.decide(waiting, false), KeyframeAction::kNone) << "and is not unexplained";
  waiting.match_failed = true;
  EXPECT_EQ(policy.decide(waiting, false), KeyframeAction::kNone) << "the first unexplained scan";
  EXPECT_EQ(policy.decide(waiting, false), KeyframeAction::kRestartMap)
      << "a second: the map lacks the view, the scan restarts it on the prediction";
  hglasm::KeyframeCandidate unexplained = scanAt(Pose2D(0.05, 0.0, 0.0));
  unexplained.match_failed = true;
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone);
  EXPECT_EQ(policy.decide(waiting, false), KeyframeAction::kRestartMap) << "after an unexplained scan";
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone);
  hglasm::KeyframeCandidate leapt = unexplained;
  leapt.leapt = true;
  EXPECT_EQ(policy.decide(leapt, false), KeyframeAction::kNone) << "a leap taken restarts nothing";
  // The wheels slipped: the far place fits as usual. The scan waits for the next one's confirmation, and
  // neither counts nor clears the unexplained scans.
  hglasm::KeyframeCandidate slipped = waiting;
  slipped.deferred_leap_fits_as_usual = true;
  EXPECT_EQ(policy.decide(slipped, false), KeyframeAction::kNone);
  EXPECT_EQ(policy.decide(slipped, false), KeyframeAction::kNone) << "however many wait";
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kRestartMap)
      << "the unexplained scan before them still counts";
}

TEST(KeyframePolicy, AfterALeapNoKeyframeUntilAScanFitsAsUsualWhereItLeapt) {
  using hglasm::KeyframeAction;
  KeyframePolicy policy = policyAt(Pose2D());
  hglasm::KeyframeCandidate leapt = scanAt(Pose2D(0.6, 0.0, 0.0));
  leapt.leapt = true;
  EXPECT_EQ(policy.decide(leapt, false), KeyframeAction::kNone);
  hglasm::KeyframeCandidate poor = scanAt(Pose2D(0.7, 0.0, 0.0));  // far enough for a keyframe
  poor.fits_as_usual = false;
  EXPECT_EQ(policy.decide(poor, false), KeyframeAction::kNone) << "the leap may be wrong: not into the map";
  EXPECT_EQ(policy.decide(poor, false), KeyframeAction::kNone) << "however many";
  EXPECT_EQ(policy.decide(poor, true), KeyframeAction::kAdd) << "an empty map takes any scan";
  hglasm::KeyframeCandidate unmatched = scanAt(Pose2D(0.7, 0.0, 0.0));
  unmatched.matched = false;
  EXPECT_EQ(policy.decide(unmatched, false), KeyframeAction::kNone) << "no match confirms the leap";
  EXPECT_EQ(policy.decide(scanAt(Pose2D(0.7, 0.0, 0.0)), false), KeyframeAction::kAdd)
      << "a scan that fits as usual there confirms it";
  policy.keyframeAdded(Pose2D(0.7, 0.0, 0.0));
  poor.pose = Pose2D(1.3, 0.0, 0.0);
  EXPECT_EQ(policy.decide(poor, false), KeyframeAction::kAdd) << "without a leap, a poor fit is no reason";

  // A restart of the map (two unexplained scans) or of the odometry forgets the leap.
  EXPECT_EQ(policy.decide(leapt, false), KeyframeAction::kNone);
  hglasm::KeyframeCandidate unexplained = scanAt(Pose2D(0.05, 0.0, 0.0));
  unexplained.match_failed = true;
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kNone);
  EXPECT_EQ(policy.decide(unexplained, false), KeyframeAction::kRestartMap);
  poor.pose = Pose2D(2.0, 0.0, 0.0);
  EXPECT_EQ(policy.decide(poor, false), KeyframeAction::kAdd) << "the map restarted";
  policy.keyframeAdded(poor.pose);
  EXPECT_EQ(policy.decide(leapt, false), KeyframeAction::kNone);
  policy.restart();
  poor.pose = Pose2D(2.6, 0.0, 0.0);
  EXPECT_EQ(policy.decide(poor, false), KeyframeAction::kAdd) << "the odometry restarted";
}

TEST(KeyframePolicy, ADueKeyframeWaitsForASlowerTurnWhileTheMapExplainsTheScan) {
  using hglasm::KeyframeAction;
  hglasm::KeyframeOptions options;
  options.angle = kAngle;
  options.max_turn_rate = 0.5;
  KeyframePolicy policy(options);
  policy.keyframeAdded(Pose2D());
  hglasm::KeyframeCandidate turning = scanAt(Pose2D(0.0, 0.0, 0.3));  // past the angle: due
  turning.turn_rate = -0.6;
  EXPECT_EQ(policy.decide(turning, false), KeyframeAction::kNone) << "turning faster than 0.5 rad/s";
  turning.pose.theta = 1.5;
  EXPECT_EQ(policy.decide(turning, false), KeyframeAction::kNone) << "however far it turned, while it fits";
  hglasm::KeyframeCandidate lost = turning;
  lost.fits_as_usual = false;
  EXPECT_EQ(policy.decide(lost, false), KeyframeAction::kAdd)
      << "the map no longer explains it: the view is needed";
  turning.turn_rate = 0.5;
  EXPECT_EQ(policy.decide(turning, false), KeyframeAction::kAdd) << "not faster than the limit";
  turning.turn_rate = 0.6;
  EXPECT_EQ(policy.decide(turning, true), KeyframeAction::kAdd) << "an empty map takes any scan";
  turning.pose.theta = 0.1;
  turning.turn_rate = 0.0;
  EXPECT_EQ(policy.decide(turning, false), KeyframeAction::kNone)
      << "a slow scan that is not due waits anyway";

  options.max_turn_rate = 0.0;  // the default: never waits
  KeyframePolicy never(options);
  never.keyframeAdded(Pose2D());
  hglasm::KeyframeCandidate fast = scanAt(Pose2D(0.0, 0.0, 0.3));
  fast.turn_rate = 3.0;
  EXPECT_EQ(never.decide(fast, false), KeyframeAction::kAdd);
}

}  // namespace
