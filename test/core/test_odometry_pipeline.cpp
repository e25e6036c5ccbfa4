// The pipeline shared by the live node and the offline tools: the wheel-odometry feeding policy, the replay
// of recorded odometry, the scanner-geometry check, the scan-error state, mirroring of an upside-down
// laser and the guess as the matcher saw it.
#include "hglasm_odometry/core/odometry_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "test_expect.h"
#include "test_util.h"

namespace {

using hglasm::OdometryPipeline;
using hglasm::PipelineUpdate;
using hglasm::Pose2D;
using hglasm::SampleVerdict;
using hglasm::TrackerOptions;

struct Sample {
  double stamp;
  Pose2D pose;
};

/// Straight along +x at 0.5 m/s from the origin.
Pose2D straightAt(double t) { return hglasm_test::rawPose(0.5 * t, 0.0, 0.0); }

/// Ranges of a laser at `laser_pose` (world frame); `upside_down`: seen from above its beams turn the other
/// way, so it is simulated with negated angles and reports the usual ones.
hglasm::RangeScan rangesAt(const Pose2D& laser_pose, bool upside_down,
                           const hglasm_test::LaserSpec& spec = hglasm_test::halfCircleLaser()) {
  hglasm_test::LaserSpec seen = spec;
  if (upside_down) {
    seen.angle_min = -spec.angle_min;
    seen.angle_increment = -spec.angle_increment;
  }
  hglasm::RangeScan ranges = hglasm_test::simulateRanges(hglasm_test::room(), laser_pose, seen);
  ranges.angle_min = spec.angle_min;
  ranges.angle_increment = spec.angle_increment;
  return ranges;
}

/// The scan of an upright laser mounted at `mount` on a robot on the straight path at time t.
hglasm::RangeScan straightScan(double t, const Pose2D& mount) {
  return rangesAt(hglasm_test::composeByHand(straightAt(t), mount), false);
}

TEST(OdometryPipeline, WaitsForOdometryAtOrAfterTheScan) {
  OdometryPipeline pipeline;
  EXPECT_TRUE(pipeline.inputsReadyFor(1.0)) << "no odometry yet: nothing to wait for";
  EXPECT_EQ(pipeline.newestOdometryStamp(), -std::numeric_limits<double>::infinity());
  ASSERT_EQ(pipeline.addOdometry(0.9, Pose2D()), SampleVerdict::kTaken);
  EXPECT_FALSE(pipeline.inputsReadyFor(1.0)) << "the sample after the scan is still to come";
  ASSERT_EQ(pipeline.addOdometry(1.0, Pose2D()), SampleVerdict::kTaken);
  EXPECT_TRUE(pipeline.inputsReadyFor(1.0)) << "a sample at the scan's stamp";
  EXPECT_FALSE(pipeline.inputsReadyFor(1.05));
  EXPECT_FALSE(pipeline.inputsReadyFor(5.0)) << "old odometry is waited for: a gap in the data, not a stop";
  pipeline.inputsWaitTimedOut(5.0);
  EXPECT_TRUE(pipeline.odometryStalled());
  EXPECT_TRUE(pipeline.inputsReadyFor(5.0)) << "after a wait timed out, odometry counts as stalled";
  EXPECT_EQ(pipeline.addOdometry(std::nan(""), Pose2D()), SampleVerdict::kInvalid);
  EXPECT_EQ(pipeline.addOdometry(2.0, Pose2D(std::nan(""), 0.0, 0.0)), SampleVerdict::kInvalid);
  EXPECT_EQ(pipeline.newestOdometryStamp(), 1.0) << "rejected samples do not count";
  EXPECT_TRUE(pipeline.odometryStalled()) << "rejected samples do not revive it either";
  ASSERT_EQ(pipeline.addOdometry(1.1, Pose2D()), SampleVerdict::kTaken);
  EXPECT_FALSE(pipeline.odometryStalled()) << "a new sample: it moves again";
  EXPECT_FALSE(pipeline.inputsReadyFor(5.0));
  EXPECT_EQ(pipeline.addOdometry(0.5, Pose2D()), SampleVerdict::kStale) << "older than the newest: dropped";
  EXPECT_EQ(pipeline.newestOdometryStamp(), 1.1) << "a dropped sample does not move the newest stamp";
}

TEST(OdometryPipeline, NeverWaitsWhenOdometryIsOffOrWaitingDisabled) {
  TrackerOptions no_odometry;
  no_odometry.prediction.use_odometry = false;
  OdometryPipeline off(no_odometry);
  off.addOdometry(0.9, Pose2D());
  EXPECT_TRUE(off.inputsReadyFor(1.0));
  OdometryPipeline no_wait(TrackerOptions(), false);
  no_wait.addOdometry(0.9, Pose2D());
  EXPECT_TRUE(no_wait.inputsReadyFor(1.0));
}

TEST(OdometryPipeline, WithUseImuTheImuIsWaitedForAndStallsOnItsOwn) {
  TrackerOptions options;
  options.prediction.use_imu = true;
  OdometryPipeline pipeline(options);
  ASSERT_EQ(pipeline.addOdometry(1.0, Pose2D()), SampleVerdict::kTaken);
  EXPECT_TRUE(pipeline.inputsReadyFor(1.0)) << "no IMU sample yet: nothing to wait for";
  ASSERT_EQ(pipeline.addImu(0.95, 0.0), SampleVerdict::kTaken);
  EXPECT_FALSE(pipeline.inputsReadyFor(1.0)) << "the wheels are there, the IMU's sample is still to come";
  ASSERT_EQ(pipeline.addImu(1.0, 0.0), SampleVerdict::kTaken);
  EXPECT_TRUE(pipeline.inputsReadyFor(1.0));
  ASSERT_EQ(pipeline.addOdometry(2.0, Pose2D()), SampleVerdict::kTaken);
  pipeline.inputsWaitTimedOut(2.0);
  EXPECT_TRUE(pipeline.imuStalled());
  EXPECT_FALSE(pipeline.odometryStalled()) << "the wheels had their sample";
  EXPECT_TRUE(pipeline.inputsReadyFor(2.0));
  EXPECT_EQ(pipeline.addImu(std::nan(""), 0.0), SampleVerdict::kInvalid);
  EXPECT_TRUE(pipeline.imuStalled()) << "a rejected sample does not revive it";
  ASSERT_EQ(pipeline.addImu(1.5, 0.0), SampleVerdict::kTaken);
  EXPECT_FALSE(pipeline.imuStalled());
  EXPECT_FALSE(pipeline.inputsReadyFor(2.0));
}

TEST(OdometryPipeline, ReplayAddsWhatTheLiveNodeHoldsAfterItsWait) {
  const std::vector<Sample> samples = {{0.8, Pose2D()}, {0.9, Pose2D()}, {1.0, Pose2D()},
                                       {1.1, Pose2D()}, {1.2, Pose2D()}, {3.5, Pose2D()}};
  OdometryPipeline pipeline;
  auto next = pipeline.addRecordedOdometry(samples.begin(), samples.end(), 0.95);
  EXPECT_EQ(next - samples.begin(), 3) << "everything up to the first sample at or after the scan";
  EXPECT_EQ(pipeline.newestOdometryStamp(), 1.0);
  next = pipeline.addRecordedOdometry(next, samples.end(), 1.0);
  EXPECT_EQ(next - samples.begin(), 3) << "a sample at the scan's stamp is enough";
  next = pipeline.addRecordedOdometry(next, samples.end(), 1.15);
  EXPECT_EQ(next - samples.begin(), 5);
  // 1.2 s to 3.5 s: a gap in the data. The replay adds the sample after it, as a live node that receives it
  // within its wait does: the scan's prediction is interpolated across the gap.
  next = pipeline.addRecordedOdometry(next, samples.end(), 2.5);
  EXPECT_EQ(next - samples.begin(), 6);
  EXPECT_TRUE(pipeline.inputsReadyFor(2.5));

  TrackerOptions no_odometry;
  no_odometry.prediction.use_odometry = false;
  OdometryPipeline off(no_odometry);
  EXPECT_EQ(off.addRecordedOdometry(samples.begin(), samples.end(), 1.0), samples.end());
  EXPECT_EQ(off.newestOdometryStamp(), -std::numeric_limits<double>::infinity()) << "nothing added";
}

TEST(OdometryPipeline, ScanErrorChangesAreReportedOnce) {
  OdometryPipeline pipeline;
  const hglasm::RangeScan good = rangesAt(Pose2D(), false);
  hglasm::RangeScan nan_increment = good;
  nan_increment.angle_increment = std::nan("");
  const hglasm::RangeScan& broken = nan_increment;
  std::vector<bool> changed;
  double t = 0.0;
  for (const hglasm::RangeScan* ranges : {&good, &broken, &broken, &good, &good}) {
    const PipelineUpdate update = pipeline.processScan(t += 0.1, *ranges);
    EXPECT_EQ(update.scan_error != hglasm::ScanError::kNone, ranges == &broken);
    changed.push_back(update.scan_error_changed);
  }
  EXPECT_EQ(changed, std::vector<bool>({false, true, false, true, false}));
}

TEST(OdometryPipeline, ImuStalenessChangesAreReportedOnce) {
  TrackerOptions options;
  options.prediction.use_odometry = false;
  options.prediction.use_imu = true;
  OdometryPipeline pipeline(options);
  const hglasm::RangeScan scan = rangesAt(Pose2D(), false);
  // The IMU sends at 200 Hz during 0.1-0.32 s and 0.58-0.8 s; as live, each scan (every 0.1 s from 0.1 s,
  // the first starts the odometry) comes after the samples stamped up to it.
  const auto sent = [](int i) { return (i >= 20 && i <= 64) || (i >= 116 && i <= 160); };
  int next = 0;
  std::vector<bool> stale, changed;
  for (int k = 1; k <= 8; ++k) {
    for (; next <= 20 * k; ++next) {
      if (sent(next)) {
        ASSERT_EQ(pipeline.addImu(0.005 * next, 0.0), SampleVerdict::kTaken);
      }
    }
    const PipelineUpdate update = pipeline.processScan(0.1 * k, scan);
    stale.push_back(update.imu_stale);
    changed.push_back(update.imu_stale_changed);
  }
  EXPECT_EQ(pipeline.addImu(std::nan(""), 0.0), SampleVerdict::kInvalid);
  // 0.2, 0.3: covered; 0.4: 0.08 s past the last sample, within max_gap; 0.5, 0.6: the gap 0.32-0.58 lies
  // in their steps; 0.7, 0.8: covered again.
  EXPECT_EQ(stale, std::vector<bool>({false, false, false, false, true, true, false, false}));
  EXPECT_EQ(changed, std::vector<bool>({false, false, false, false, true, false, true, false}));
}

TEST(OdometryPipeline, TheImuIsWaitedForToTheEndOfTheSweep) {
  // De-skewing takes the IMU's turn during the sweep; the wheels are needed at the stamp only.
  TrackerOptions options;
  options.prediction.use_imu = true;
  OdometryPipeline pipeline(options);
  ASSERT_EQ(pipeline.addOdometry(1.0, Pose2D()), SampleVerdict::kTaken);
  ASSERT_EQ(pipeline.addImu(1.05, 0.0), SampleVerdict::kTaken);
  EXPECT_TRUE(pipeline.inputsReadyFor(1.0));
  EXPECT_FALSE(pipeline.inputsReadyFor(1.0, 0.1));
  ASSERT_EQ(pipeline.addImu(1.1, 0.0), SampleVerdict::kTaken);
  EXPECT_TRUE(pipeline.inputsReadyFor(1.0, 0.1));
  EXPECT_FALSE(pipeline.inputsReadyFor(1.0, 0.2));
  // What a live wait wakes for: the IMU sample at the sweep's end, no wheel sample (they are there).
  const hglasm::AwaitedStamps awaited = pipeline.awaitedFor(1.0, 0.2);
  EXPECT_EQ(awaited.wheels, std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(awaited.imu, 1.2);
  EXPECT_EQ(pipeline.awaitedFor(1.3, 0.0).wheels, 1.3);
  pipeline.inputsWaitTimedOut(1.0, 0.2);
  EXPECT_TRUE(pipeline.imuStalled());
  EXPECT_FALSE(pipeline.odometryStalled());
}

TEST(OdometryPipeline, AStalledInputIsRevivedOnlyBySamplesAtOrAfterTheLastScan) {
  // An IMU whose samples lag by more than the live wait is not waited for at every scan.
  TrackerOptions options;
  options.prediction.use_odometry = false;
  options.prediction.use_imu = true;
  OdometryPipeline pipeline(options);
  const hglasm::RangeScan scan = rangesAt(Pose2D(), false);
  ASSERT_EQ(pipeline.addImu(0.5, 0.0), SampleVerdict::kTaken);
  ASSERT_FALSE(pipeline.inputsReadyFor(1.0));
  pipeline.inputsWaitTimedOut(1.0);
  EXPECT_TRUE(pipeline.imuStalled());
  pipeline.processScan(1.0, scan);
  ASSERT_EQ(pipeline.addImu(0.8, 0.0), SampleVerdict::kTaken);  // late: older than the scan already processed
  EXPECT_TRUE(pipeline.imuStalled());
  EXPECT_TRUE(pipeline.inputsReadyFor(1.1)) << "not waited for";
  ASSERT_EQ(pipeline.addImu(1.0, 0.0), SampleVerdict::kTaken);  // caught up with the scans
  EXPECT_FALSE(pipeline.imuStalled());
  EXPECT_FALSE(pipeline.inputsReadyFor(1.1));
}

TEST(OdometryPipeline, WithoutUseImuNothingIsStale) {
  OdometryPipeline pipeline;
  EXPECT_EQ(pipeline.addImu(0.0, 1.0), SampleVerdict::kInvalid);
  const hglasm::RangeScan scan = rangesAt(Pose2D(), false);
  for (int i = 1; i <= 3; ++i) {
    const PipelineUpdate update = pipeline.processScan(0.1 * i, scan);
    EXPECT_FALSE(update.imu_stale);
    EXPECT_FALSE(update.imu_stale_changed);
    EXPECT_FALSE(update.tracker.diagnostics.rotation_from_imu);
  }
}

/// An upside-down laser mounted off-centre and turned: tracked only if the pipeline mirrors its scans, and
/// the guess it reports is the laser's predicted pose in the keyframe's laser frame (next to the match).
TEST(OdometryPipeline, MirrorsAnUpsideDownLaserAndReportsTheGuessInTheLaserFrame) {
  const Pose2D mount(0.3, 0.1, 0.4);
  OdometryPipeline pipeline;
  EXPECT_FALSE(pipeline.setLaserMount(Pose2D(std::nan(""), 0.0, 0.0), true));
  EXPECT_FALSE(pipeline.conversion().mirror) << "a rejected mount changes nothing";
  ASSERT_TRUE(pipeline.setLaserMount(mount, true));
  EXPECT_TRUE(pipeline.conversion().mirror);
  int guesses = 0;
  PipelineUpdate update;
  std::vector<Sample> odometry;  // perfect wheel odometry at 50 Hz
  for (int k = 0; k <= 110; ++k) odometry.push_back({0.02 * k, straightAt(0.02 * k)});
  auto next_odometry = odometry.begin();
  for (int i = 0; i <= 20; ++i) {
    const double t = 0.1 * i;
    next_odometry = pipeline.addRecordedOdometry(next_odometry, odometry.end(), t);
    const Pose2D laser = hglasm_test::composeByHand(straightAt(t), mount);
    update = pipeline.processScan(t, rangesAt(laser, true));
    ASSERT_TRUE(update.tracker.published);
    EXPECT_EQ(update.laser_guess.has_value(), update.tracker.matched);
    if (!update.laser_guess) continue;
    ++guesses;
    // Perfect odometry: the guess is where the match lands (a wrong frame would be 0.1 m / 0.4 rad off).
    hglasm_test::expectPoseNear(*update.laser_guess, update.tracker.diagnostics.match.pose, 0.01, 0.005,
                                "guess vs match at " + std::to_string(t));
  }
  EXPECT_EQ(guesses, 20);
  hglasm_test::expectPoseNear(update.tracker.pose, straightAt(2.0), 0.02, 0.01, "final pose");
}

TEST(OdometryPipeline, ResetRestartsAtTheOriginAndKeepsTheMount) {
  TrackerOptions options;
  options.prediction.use_odometry = false;
  OdometryPipeline pipeline(options);
  const Pose2D mount(0.3, 0.1, 0.4);
  pipeline.setLaserMount(mount, false);
  for (int i = 0; i <= 5; ++i) {
    const double t = 0.1 * i;
    pipeline.processScan(t, straightScan(t, mount));
  }
  EXPECT_GT(pipeline.pose().x, 0.2);
  pipeline.reset();
  const PipelineUpdate first = pipeline.processScan(0.6, straightScan(0.6, mount));
  EXPECT_TRUE(first.tracker.reset);
  EXPECT_EQ(first.tracker.pose.x, 0.0);
  const PipelineUpdate second = pipeline.processScan(0.7, straightScan(0.7, mount));
  ASSERT_TRUE(second.laser_guess.has_value());
  // From the new keyframe (the origin): 5 cm ahead, seen from the mounted laser.
  hglasm_test::expectPoseNear(second.tracker.pose, Pose2D(0.05, 0.0, 0.0), 0.01, 0.005, "after reset");
  hglasm_test::expectPoseNear(second.tracker.diagnostics.match.pose,
                              mount.inverse() * Pose2D(0.05, 0.0, 0.0) * mount, 0.01, 0.005,
                              "match after reset");
}

TEST(OdometryPipeline, SetPoseRestartsFromThePoseAndKeepsTheMount) {
  TrackerOptions options;
  options.prediction.use_odometry = false;
  OdometryPipeline pipeline(options);
  const Pose2D mount(0.3, 0.1, 0.4);
  pipeline.setLaserMount(mount, false);
  for (int i = 0; i <= 5; ++i) {
    const double t = 0.1 * i;
    pipeline.processScan(t, straightScan(t, mount));
  }
  const Pose2D set(5.0, -2.0, 1.0);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity() * 0.01;
  EXPECT_FALSE(pipeline.setPose(0.6, set, -covariance));
  ASSERT_TRUE(pipeline.setPose(0.6, set, covariance));
  hglasm_test::expectPoseNear(pipeline.pose(), set, 1e-12, 1e-12, "pipeline.pose()");
  const PipelineUpdate first = pipeline.processScan(0.6, straightScan(0.6, mount));
  EXPECT_TRUE(first.tracker.reset);
  hglasm_test::expectPoseNear(first.tracker.pose, set, 1e-12, 1e-12, "first.tracker.pose");
  EXPECT_TRUE(first.tracker.pose_covariance.isApprox(covariance, 1e-12));
  const PipelineUpdate second = pipeline.processScan(0.7, straightScan(0.7, mount));
  ASSERT_TRUE(second.laser_guess.has_value());
  hglasm_test::expectPoseNear(second.tracker.pose, set * Pose2D(0.05, 0.0, 0.0), 0.01, 0.005, "after set");
  // The guess is relative to the new keyframe at the set pose: the identity (no motion known yet).
  hglasm_test::expectPoseNear(*second.laser_guess, Pose2D(), 1e-9, 1e-9, "guess after set");
  hglasm_test::expectPoseNear(second.tracker.diagnostics.match.pose,
                              mount.inverse() * Pose2D(0.05, 0.0, 0.0) * mount, 0.01, 0.005,
                              "match after set");
}

/// The local map the pipeline exposes (the node's ~local_map): the newest keyframe's laser pose is its
/// frame, its points lie on the room's walls once moved into the odometry frame, and its revision changes
/// exactly at the scans that made a keyframe.
TEST(OdometryPipeline, ExposesTheLocalMapInTheOdometryFrameAndItsRevisionPerKeyframe) {
  TrackerOptions options;
  options.prediction.use_odometry = false;
  options.keyframe.distance = 0.3;
  OdometryPipeline pipeline(options);
  const Pose2D mount(0.3, 0.1, 0.4);
  pipeline.setLaserMount(mount, false);
  EXPECT_TRUE(pipeline.localMap().empty());
  auto revision = pipeline.localMap().revision();
  int keyframes = 0;
  for (int i = 0; i <= 20; ++i) {
    const double t = 0.1 * i;
    const PipelineUpdate update = pipeline.processScan(t, straightScan(t, mount));
    ASSERT_TRUE(update.tracker.published);
    const bool changed = pipeline.localMap().revision() != revision;
    revision = pipeline.localMap().revision();
    EXPECT_EQ(changed, update.tracker.new_keyframe) << "scan " << i;
    keyframes += update.tracker.new_keyframe;
    if (!update.tracker.new_keyframe) continue;
    // The map's frame is a keyframe's laser pose within reframe_distance of the newest.
    const Pose2D newest = update.tracker.pose * mount;
    const Pose2D frame = pipeline.localMap().frame();
    EXPECT_LT((frame.translation() - newest.translation()).norm(), options.local_map.reframe_distance)
        << "scan " << i;
    if (pipeline.localMap().unchangedScans() == 0)
      hglasm_test::expectPoseNear(frame, newest, 1e-9, 1e-9, "map frame");
  }
  EXPECT_GE(keyframes, 3) << "1 m at 0.30 m per keyframe";
  const hglasm::LocalMap& map = pipeline.localMap();
  ASSERT_FALSE(map.reference().empty());
  // Moved into the odometry frame (= the room's frame: the run starts at its origin), the points lie on
  // what the laser saw from its true poses: within a few cm of the points simulated there.
  std::vector<Eigen::Vector2d> room;
  for (int i = 0; i <= 20; ++i) {
    const Pose2D truth_pose = hglasm_test::composeByHand(straightAt(0.1 * i), mount);
    const hglasm::Scan truth = hglasm::scanFromRanges(rangesAt(truth_pose, false), options.conversion);
    for (const Eigen::Vector2d& p : truth.points) room.push_back(truth_pose * p);
  }
  int near = 0;
  for (const Eigen::Vector2d& p : map.reference().points) {
    const Eigen::Vector2d in_odom = map.frame() * p;
    double best = 1e9;
    for (const Eigen::Vector2d& q : room) best = std::min(best, (q - in_odom).norm());
    near += best < 0.05;
  }
  EXPECT_GT(near, 0.8 * map.reference().size());
  pipeline.reset();
  pipeline.processScan(2.1, straightScan(2.1, mount));
  EXPECT_NE(pipeline.localMap().revision(), revision) << "a reset rebuilds the map";
}

}  // namespace

namespace {

TEST(OdometryPipeline, TimePolicyAStaleScanIsDroppedAndWaitsForNothing) {
  TrackerOptions options;
  options.prediction.use_odometry = false;
  OdometryPipeline pipeline(options);
  pipeline.processScan(1.0, straightScan(1.0, Pose2D()));
  pipeline.processScan(1.1, straightScan(1.1, Pose2D()));
  const Pose2D before = pipeline.pose();
  EXPECT_TRUE(pipeline.inputsReadyFor(1.099));
  const PipelineUpdate stale = pipeline.processScan(1.099, straightScan(1.099, Pose2D()));
  EXPECT_TRUE(stale.tracker.stale);
  EXPECT_FALSE(stale.tracker.published);
  EXPECT_FALSE(stale.tracker.reset);
  EXPECT_FALSE(stale.jumped_back);
  EXPECT_NE(stale.tracker.warning.find("before the last one processed"), std::string::npos)
      << stale.tracker.warning;
  EXPECT_EQ(pipeline.pose().x, before.x);
  EXPECT_EQ(pipeline.inputCounts().stale_scans, 1u);
  const PipelineUpdate next = pipeline.processScan(1.2, straightScan(1.2, Pose2D()));
  EXPECT_TRUE(next.tracker.published);
  EXPECT_FALSE(next.tracker.reset);
}

TEST(OdometryPipeline, TimePolicyOdometryOlderThanItsNewestIsDroppedAndMuchOlderIsANewTimeline) {
  OdometryPipeline pipeline;
  ASSERT_EQ(pipeline.addOdometry(10.0, Pose2D()), SampleVerdict::kTaken);
  EXPECT_EQ(pipeline.addOdometry(9.9, Pose2D()), SampleVerdict::kStale);
  EXPECT_EQ(pipeline.addOdometry(10.0, Pose2D()), SampleVerdict::kTaken) << "the same stamp again";
  EXPECT_EQ(pipeline.inputCounts().stale_odometry, 1u);
  EXPECT_EQ(pipeline.addOdometry(2.0, Pose2D()), SampleVerdict::kNewTimeline);
  EXPECT_EQ(pipeline.newestOdometryStamp(), 2.0);
  EXPECT_EQ(pipeline.addOdometry(2.1, Pose2D()), SampleVerdict::kTaken);
}

TEST(OdometryPipeline, TimePolicyAScanClockThatJumpsBackRestartsAndForgetsTheOldWheels) {
  // A looped bag: scans and wheels start again 20 s earlier, the scans first. The old timeline's wheels
  // would make the first predictions jumps; they are forgotten, and the wheels of the new one predict.
  OdometryPipeline pipeline;
  for (int i = 0; i <= 20; ++i) {
    const double t = 0.05 * i;  // seen at t, stamped 20 s later
    pipeline.addOdometry(20.0 + t, straightAt(t));
    if (i % 2 == 0) pipeline.processScan(20.0 + t, straightScan(t, Pose2D()));
  }
  const PipelineUpdate back = pipeline.processScan(0.0, straightScan(0.0, Pose2D()));
  EXPECT_TRUE(back.jumped_back);
  EXPECT_TRUE(back.tracker.reset);
  EXPECT_NE(back.tracker.warning.find("went back by 21"), std::string::npos) << back.tracker.warning;
  EXPECT_EQ(pipeline.newestOdometryStamp(), -std::numeric_limits<double>::infinity()) << "forgotten";
  for (int i = 1; i <= 10; ++i) {
    const double t = 0.05 * i;
    EXPECT_EQ(pipeline.addOdometry(t, straightAt(t)), SampleVerdict::kTaken);
    if (i % 2) continue;
    const PipelineUpdate update = pipeline.processScan(t, straightScan(t, Pose2D()));
    EXPECT_EQ(update.tracker.diagnostics.prediction, hglasm::PredictionSource::kOdometry) << t;
    EXPECT_FALSE(update.tracker.reset);
    EXPECT_TRUE(update.tracker.warning.empty()) << update.tracker.warning;
  }
  EXPECT_NEAR(pipeline.pose().x, straightAt(0.5).x - straightAt(0.0).x, 0.01);
  EXPECT_EQ(pipeline.inputCounts().jumps_back, 1u);
}

TEST(OdometryPipeline, AScanIsReadyExactlyWhenItAwaitsNothing) {
  // What a live wait wakes for (awaitedFor) and when it may go on (inputsReadyFor) are one rule.
  TrackerOptions options;
  options.prediction.use_imu = true;
  OdometryPipeline pipeline(options);
  const auto check = [&pipeline](double stamp, double sweep, bool ready, const char* state) {
    const hglasm::AwaitedStamps awaited = pipeline.awaitedFor(stamp, sweep);
    EXPECT_EQ(pipeline.inputsReadyFor(stamp, sweep), ready) << state;
    EXPECT_EQ(awaited.nothing(), ready) << state;
  };
  check(1.0, 0.1, true, "no samples yet");
  ASSERT_EQ(pipeline.addOdometry(0.9, Pose2D()), SampleVerdict::kTaken);
  ASSERT_EQ(pipeline.addImu(0.9, 0.0), SampleVerdict::kTaken);
  check(1.0, 0.1, false, "both behind");
  EXPECT_EQ(pipeline.awaitedFor(1.0, 0.1).wheels, 1.0);
  EXPECT_DOUBLE_EQ(pipeline.awaitedFor(1.0, 0.1).imu, 1.1);
  ASSERT_EQ(pipeline.addOdometry(1.2, Pose2D()), SampleVerdict::kTaken);
  check(1.0, 0.1, false, "the IMU behind");
  EXPECT_EQ(pipeline.awaitedFor(1.0, 0.1).wheels, std::numeric_limits<double>::infinity());
  pipeline.inputsWaitTimedOut(1.0, 0.1);
  check(1.0, 0.1, true, "the IMU stalled");
  ASSERT_EQ(pipeline.addImu(1.2, 0.0), SampleVerdict::kTaken);
  check(1.0, 0.1, true, "both there");
  const PipelineUpdate first = pipeline.processScan(1.0, straightScan(1.0, Pose2D()));
  ASSERT_FALSE(first.tracker.stale);
  check(0.95, 0.5, true, "a scan the time policy drops (its sweep's IMU not there)");
  check(1.05, 0.5, false, "the same sweep after the last scan");
  check(5.0, 0.1, false, "wheels and IMU behind a later scan");
  TrackerOptions wheels_off = options;
  wheels_off.prediction.use_odometry = false;
  wheels_off.prediction.use_imu = false;
  OdometryPipeline off(wheels_off);
  ASSERT_EQ(off.addOdometry(0.9, Pose2D()), SampleVerdict::kTaken);
  EXPECT_TRUE(off.awaitedFor(5.0).nothing()) << "inputs not used are not awaited";
}

TEST(OdometryPipeline, LateWheelsAreWaitedForByTheirTimeOffset) {
  TrackerOptions options;
  options.learning.odometry_time_offset.estimate = false;
  options.learning.odometry_time_offset.offset = 0.3;
  OdometryPipeline pipeline(options);
  EXPECT_EQ(pipeline.odometryTimeOffset(), 0.3);
  ASSERT_EQ(pipeline.addOdometry(1.0, Pose2D()), SampleVerdict::kTaken);
  EXPECT_FALSE(pipeline.inputsReadyFor(1.0)) << "their pose of 1.0 s comes stamped 1.3 s";
  EXPECT_DOUBLE_EQ(pipeline.awaitedFor(1.0).wheels, 1.3);
  EXPECT_EQ(pipeline.awaitedFor(1.0).imu, std::numeric_limits<double>::infinity()) << "no use_imu";
  ASSERT_EQ(pipeline.addOdometry(1.3, Pose2D()), SampleVerdict::kTaken);
  EXPECT_TRUE(pipeline.inputsReadyFor(1.0));
  EXPECT_EQ(pipeline.awaitedFor(1.0).wheels, std::numeric_limits<double>::infinity());
}

}  // namespace
