// The core rows of the robustness matrix (issue 5): bad scans, changing scan geometry, odd laser layouts,
// time faults and wheel-odometry faults fed to the OdometryPipeline, the entry point of the nodelet and
// the offline tools (RangeScan in, its conversion, time policy and tracker). Every update must be finite
// and every fault must be visible in the update (fallback, prediction source, reset, stale, warning).
//
// Rows already covered elsewhere (not repeated here): duplicate stamps
// (test_odometry_tracker.cpp DuplicateStampsNeverGiveNaN), the time policy's single cases
// (test_odometry_pipeline.cpp TimePolicy*), no wheel odometry at all (FollowsACircleWithoutWheelOdometry),
// an empty Scan{} (EmptyScansFallBackToTheOdometryGuess).
#include "hglasm_odometry/core/odometry_pipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "simulated_robot.h"
#include "test_expect.h"
#include "test_util.h"

namespace {

using hglasm::OdometryPipeline;
using hglasm::OdometryTracker;
using hglasm::Pose2D;
using hglasm::PredictionSource;
using hglasm::RangeScan;
using hglasm::TrackerOptions;
using hglasm::TrackerUpdate;
using hglasm_test::deg;
using hglasm_test::expectPoseNear;
using hglasm_test::LaserSpec;
using hglasm_test::Path;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

/// Clockwise circle of radius 1.5 m through the origin at 0.5 m/s (clear of the room's obstacles).
Pose2D circlePath(double t) {
  const double radius = 1.5, rate = 0.5 / radius;
  return hglasm_test::rawPose(radius * std::sin(rate * t), -radius + radius * std::cos(rate * t),
                              hglasm_test::angleDiff(-rate * t, 0.0));
}

/// Forward at `speed` while turning at `rate`: with a 360-degree laser the +-pi seam sweeps over the room.
Path arcPath(double speed, double rate) {
  return [speed, rate](double t) {
    if (std::abs(rate) < 1e-12) return hglasm_test::rawPose(speed * t, 0.0, 0.0);
    const double r = speed / rate;
    return hglasm_test::rawPose(r * std::sin(rate * t), r - r * std::cos(rate * t),
                                hglasm_test::angleDiff(rate * t, 0.0));
  };
}

std::string describe(const TrackerUpdate& u) {
  std::ostringstream text;
  text << "stamp " << u.stamp << " pose " << u.pose.x << " " << u.pose.y << " " << u.pose.theta << " matched "
       << u.matched << " fallback " << u.fallback << " status "
       << hglasm::toString(u.diagnostics.match.status) << " fitness " << u.diagnostics.fitness_ratio
       << " prediction " << hglasm::toString(u.diagnostics.prediction) << " keyframe " << u.new_keyframe
       << " reset " << u.reset << " warning '" << u.warning << "'";
  return text.str();
}

/// Never NaN, never an invalid covariance, whatever went in.
void expectSane(const TrackerUpdate& u) {
  EXPECT_TRUE(u.pose.isFinite()) << describe(u);
  EXPECT_TRUE(u.diagnostics.guess.isFinite()) << describe(u);
  EXPECT_TRUE(u.velocity.allFinite()) << describe(u);
  EXPECT_TRUE(hglasm_test::isValidCovariance(u.pose_covariance)) << describe(u) << "\n" << u.pose_covariance;
  EXPECT_TRUE(hglasm_test::isValidCovariance(u.velocity_covariance)) << describe(u);
  EXPECT_TRUE(u.diagnostics.match.pose.isFinite()) << describe(u);
  EXPECT_TRUE(u.diagnostics.match.covariance.allFinite()) << describe(u);
}

/// The simulated robot (simulated_robot.h) feeding the pipeline the nodelet runs: its wheel odometry
/// (optional, 50 Hz from t = 0, can be delayed or corrupted) up to each scan, then the scan.
class Robot {
 public:
  Robot(const TrackerOptions& options, Path path, LaserSpec laser = hglasm_test::halfCircleLaser(),
        hglasm_test::World world = hglasm_test::room())
      : pipeline_(options), sim_(std::move(path), std::move(world), laser, -0.02) {}

  void setLaser(const LaserSpec& laser) { sim_.setLaser(laser); }
  /// Exact wheel odometry (the truth), optionally with a permanent offset added from `jump_time` on.
  void enableOdometry(double jump_time = std::numeric_limits<double>::infinity(),
                      const Pose2D& jump = Pose2D()) {
    sim_.enableWheels();
    sim_.setWheelJump(jump_time, jump);
  }
  /// The wheels report this path instead of the true one (their own errors).
  void setOdometryPath(Path path) { sim_.wheels().setPath(std::move(path)); }
  /// Odometry samples are handed to the tracker only `delay` seconds after their stamp.
  void setOdometryDelay(double delay) { sim_.setWheelDelay(delay); }

  Pose2D truth(double t) const { return sim_.truth(t); }
  RangeScan rangesAt(double t) const { return sim_.rangesAt(t); }

  /// The clock of the scans and the odometry is ahead of the simulated time by `offset` from now on.
  void setStampOffset(double offset) { sim_.setStampOffset(offset); }

  /// Feeds the odometry available at wall time t (stamps <= t - delay), then the scan taken at t.
  TrackerUpdate step(double t, const RangeScan* ranges = nullptr) {
    return stepAt(t, sim_.stampOf(t), ranges);
  }

  /// The next scan's time, 0.1 s after the last one's.
  double nextTime() const { return last_time_ + 0.1; }

  /// As step(), but the scan carries `stamp` (time faults) while the world is seen at `t`.
  TrackerUpdate stepAt(double t, double stamp, const RangeScan* ranges = nullptr) {
    last_time_ = t;
    hglasm_test::RobotSink sink;
    sink.wheels = [this](double wheel_stamp, const Pose2D& pose) {
      pipeline_.addOdometry(wheel_stamp, pose);
    };
    sim_.advanceTo(t, sink);
    const RangeScan scan = ranges ? *ranges : rangesAt(t);
    const hglasm::PipelineUpdate result = pipeline_.processScan(stamp, scan);
    last_error_ = result.scan_error;
    expectSane(result.tracker);
    if (!result.tracker.warning.empty()) warnings_.push_back(result.tracker.warning);
    return result.tracker;
  }

  OdometryPipeline& pipeline() { return pipeline_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  hglasm::ScanError lastError() const { return last_error_; }

 private:
  OdometryPipeline pipeline_;
  hglasm_test::SimulatedRobot sim_;
  double last_time_ = 0.0;
  std::vector<std::string> warnings_;
  hglasm::ScanError last_error_ = hglasm::ScanError::kNone;
};

TrackerOptions withoutOdometry() {
  TrackerOptions options;
  options.prediction.use_odometry = false;
  return options;
}

// ------------------------------------------------------------------ bad scans

/// The three "nothing to match" scans, as a driver could publish them.
std::vector<std::pair<std::string, RangeScan>> unusableScans(const RangeScan& good) {
  std::vector<std::pair<std::string, RangeScan>> scans;
  RangeScan empty = good;
  empty.ranges.clear();
  scans.emplace_back("no beams", empty);
  RangeScan invalid = good;
  const float bad[] = {kNaN,
                       kInf,
                       -kInf,
                       0.0f,
                       -1.0f,
                       static_cast<float>(good.range_max) + 5.0f,
                       static_cast<float>(good.range_min) * 0.5f};
  for (std::size_t i = 0; i < invalid.ranges.size(); ++i) invalid.ranges[i] = bad[i % 7];
  scans.emplace_back("all ranges invalid", invalid);
  RangeScan single = invalid;
  single.ranges[single.ranges.size() / 2] = 2.0f;
  scans.emplace_back("a single valid point", single);
  return scans;
}

TEST(Robustness, UnusableScansAreFlaggedAndIntegrateTheOdometryGuess) {
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry();  // exact wheel odometry: the fallback must follow it
  for (int i = 0; i <= 10; ++i) robot.step(0.1 * i);
  double previous_trace = robot.step(1.1).pose_covariance.trace();
  int i = 12;
  for (const auto& [what, ranges] : unusableScans(robot.rangesAt(0.0))) {
    SCOPED_TRACE(what);
    for (int k = 0; k < 3; ++k, ++i) {
      const TrackerUpdate update = robot.step(0.1 * i, &ranges);
      EXPECT_TRUE(update.published) << describe(update);
      EXPECT_TRUE(update.fallback) << describe(update);
      EXPECT_FALSE(update.new_keyframe) << describe(update);  // the keyframe is kept for when scans return
      EXPECT_EQ(update.diagnostics.match.status, hglasm::MatchStatus::kTooFewPoints) << describe(update);
      EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry) << describe(update);
      expectPoseNear(update.pose, robot.truth(0.1 * i), 0.005, deg(0.1), describe(update));
      EXPECT_GT(update.pose_covariance.trace(), previous_trace) << describe(update);  // uncertainty grows
      previous_trace = update.pose_covariance.trace();
    }
  }
  // Unusable scans are flagged, not warned about (the ROS layer reports a broken scan once).
  EXPECT_TRUE(robot.warnings().empty()) << robot.warnings().front();
  // Valid scans again: tracking resumes with matches, not fallbacks.
  TrackerUpdate update;
  for (int k = 0; k < 10; ++k, ++i) {
    update = robot.step(0.1 * i);
    EXPECT_TRUE(update.matched) << describe(update);
    EXPECT_FALSE(update.fallback) << describe(update);
  }
  expectPoseNear(update.pose, robot.truth(0.1 * (i - 1)), 0.02, deg(0.3), "after the bad scans");
}

TEST(Robustness, AScanTheMapCannotExplainStaysOutOfItAndASecondInARowReanchorsIt) {
  // One scan of another place (someone standing in front of the laser, a door swinging by) is an outlier:
  // the wheels carry the pose and the map stays. Two in a row say the map no longer describes where the
  // robot is (it was moved during a pause): the map restarts from the second.
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry();
  for (int i = 0; i <= 20; ++i) robot.step(0.1 * i);
  const auto elsewhere = [&](double t) {
    return hglasm_test::simulateRanges(hglasm_test::corridor(0.6, 200.0), robot.truth(t),
                                       hglasm_test::halfCircleLaser());
  };
  hglasm::RangeScan foreign = elsewhere(2.1);
  TrackerUpdate update = robot.step(2.1, &foreign);
  ASSERT_TRUE(update.fallback) << describe(update);
  EXPECT_FALSE(update.diagnostics.reanchored) << describe(update);
  EXPECT_FALSE(update.new_keyframe) << describe(update) << ": an outlier never enters the map";
  const int keyframes = update.keyframe_id;
  update = robot.step(2.2);
  EXPECT_FALSE(update.fallback) << describe(update) << ": the map still holds";
  expectPoseNear(update.pose, robot.truth(2.2), 0.02, deg(0.3), describe(update));
  foreign = elsewhere(2.3);
  update = robot.step(2.3, &foreign);
  EXPECT_TRUE(update.fallback && !update.diagnostics.reanchored) << describe(update);
  foreign = elsewhere(2.4);
  update = robot.step(2.4, &foreign);
  EXPECT_TRUE(update.diagnostics.reanchored) << describe(update);
  EXPECT_TRUE(update.new_keyframe) << describe(update);
  EXPECT_GT(update.keyframe_id, keyframes);
  EXPECT_EQ(robot.pipeline().localMap().keyframeCount(), 1u) << "the map restarted from it";
}

TEST(Robustness, UnusableScansWithoutOdometryKeepTheConstantVelocity) {
  Robot robot(withoutOdometry(), arcPath(0.4, 0.1));
  for (int i = 0; i <= 10; ++i) robot.step(0.1 * i);
  int i = 11;
  for (const auto& [what, ranges] : unusableScans(robot.rangesAt(0.0))) {
    SCOPED_TRACE(what);
    const TrackerUpdate update = robot.step(0.1 * i++, &ranges);
    EXPECT_TRUE(update.fallback) << describe(update);
    EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kConstantVelocity) << describe(update);
  }
  // 0.3 s of constant-velocity prediction on a gentle arc stays within a few millimetres.
  expectPoseNear(robot.pipeline().pose(), robot.truth(0.1 * (i - 1)), 0.01, deg(0.2), "after the bad scans");
}

TEST(Robustness, StructurallyBrokenScansAreFallbacksToo) {
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry();
  for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
  RangeScan zero_increment = robot.rangesAt(0.6);
  zero_increment.angle_increment = 0.0;
  RangeScan nan_angle = robot.rangesAt(0.7);
  nan_angle.angle_min = std::numeric_limits<double>::quiet_NaN();
  RangeScan bad_limits = robot.rangesAt(0.8);
  bad_limits.range_min = 10.0;
  bad_limits.range_max = 1.0;
  int i = 6;
  for (const RangeScan* scan : {&zero_increment, &nan_angle, &bad_limits}) {
    const TrackerUpdate update = robot.step(0.1 * i, scan);
    EXPECT_NE(robot.lastError(), hglasm::ScanError::kNone);
    EXPECT_TRUE(update.fallback) << describe(update);
    expectPoseNear(update.pose, robot.truth(0.1 * i), 0.005, deg(0.1), describe(update));
    ++i;
  }
}

TEST(Robustness, InvalidRangesMixedInLeaveTheEstimateUnchanged) {
  // Two identical robots; one laser reports a third of its beams as NaN, +-inf, 0, negative, below
  // range_min or beyond range_max (REP-117: all invalid). Both estimates must agree.
  Robot clean(withoutOdometry(), circlePath);
  Robot dirty(withoutOdometry(), circlePath);
  const float bad[] = {kNaN, kInf, -kInf, 0.0f, -3.0f, 0.01f, 45.0f, 1e30f};
  TrackerUpdate a, b;
  for (int i = 0; i <= 60; ++i) {
    const double t = 0.1 * i;
    RangeScan ranges = clean.rangesAt(t);
    a = clean.step(t, &ranges);
    for (std::size_t k = (i % 3); k < ranges.ranges.size(); k += 3) ranges.ranges[k] = bad[(k / 3 + i) % 8];
    b = dirty.step(t, &ranges);
    if (i == 0) continue;
    EXPECT_FALSE(b.fallback) << describe(b);
    expectPoseNear(b.pose, a.pose, 0.01, deg(0.2), "dirty vs clean at scan " + std::to_string(i));
  }
  expectPoseNear(b.pose, clean.truth(6.0), 0.03, deg(0.5), "dirty vs truth");
}

// ------------------------------------------------------------------ scanner geometry

TEST(Robustness, ADriverReconfiguredToAnotherGeometryNeedsNoKeyframe) {
  // 270 degrees with 541 beams instead of 180 degrees with 361, then 240 degrees with 361 beams (the same
  // beam count, another increment): the points stay metric, so the map they are matched against is kept.
  Robot robot(withoutOdometry(), circlePath);
  for (int i = 0; i <= 15; ++i) robot.step(0.1 * i);
  for (const LaserSpec& laser :
       {hglasm_test::laserSpec(deg(270.0), 541), hglasm_test::laserSpec(deg(240.0), 361)}) {
    robot.setLaser(laser);
    const TrackerUpdate changed = robot.step(robot.nextTime());
    EXPECT_FALSE(changed.fallback) << describe(changed);
    EXPECT_FALSE(changed.reset) << describe(changed);
    EXPECT_GT(changed.diagnostics.map_keyframes, 1)
        << "the map of the earlier scans was kept: " << describe(changed);
    TrackerUpdate update;
    for (int i = 0; i < 12; ++i) {
      update = robot.step(robot.nextTime());
      EXPECT_TRUE(update.matched) << describe(update);
      EXPECT_FALSE(update.fallback) << describe(update);
    }
    expectPoseNear(update.pose, robot.truth(update.stamp), 0.03, deg(0.5), "after the change");
  }
  EXPECT_TRUE(robot.warnings().empty()) << robot.warnings().front();
}

struct LaserCase {
  std::string name;
  LaserSpec laser;
  Path path;
  double seconds;
};

class LaserLayouts : public testing::TestWithParam<int> {};

std::vector<LaserCase> laserCases() {
  return {
      {"descending_180deg", hglasm_test::laserSpec(hglasm_test::kPi, 361, true), circlePath, 5.0},
      {"descending_270deg_1081", hglasm_test::laserSpec(deg(270.0), 1081, true), circlePath, 4.0},
      // Full turn and a half on an arc: the seam at +-pi sweeps over every wall.
      {"full_circle_across_the_seam", hglasm_test::fullCircleLaser(360), arcPath(0.2, 0.8), 12.0},
      {"full_circle_descending", hglasm_test::laserSpec(2.0 * hglasm_test::kPi, 720, true),
       arcPath(0.2, -0.8), 8.0},
      {"more_than_2000_beams", hglasm_test::laserSpec(deg(270.0), 2161), circlePath, 4.0},
      {"full_circle_4000_beams", hglasm_test::fullCircleLaser(4000), arcPath(0.3, 0.5), 4.0},
  };
}

TEST_P(LaserLayouts, CorrectEstimate) {
  const LaserCase c = laserCases()[GetParam()];
  Robot robot(withoutOdometry(), c.path, c.laser);
  TrackerUpdate update;
  int fallbacks = 0;
  const int steps = static_cast<int>(std::lround(c.seconds * 10.0));
  for (int i = 0; i <= steps; ++i) {
    update = robot.step(0.1 * i);
    if (i > 0 && update.fallback) ++fallbacks;
  }
  EXPECT_EQ(fallbacks, 0);
  EXPECT_TRUE(robot.warnings().empty()) << robot.warnings().front();
  expectPoseNear(update.pose, robot.truth(0.1 * steps), 0.03, deg(0.5), c.name);
}

INSTANTIATE_TEST_SUITE_P(Robustness, LaserLayouts, testing::Range(0, 6),
                         [](const testing::TestParamInfo<int>& info) {
                           return laserCases()[info.param].name;
                         });

// ------------------------------------------------------------------ time faults

TEST(Robustness, LoopedSequenceResetsOnceAndRepeatsItself) {
  // A bag played with --loop: the stamps jump back to the start, 4 s (more than reset_on_jump_back). One
  // reset, one warning, and the second pass reproduces the first (same scans from the same origin; the
  // tracker's GA seed is per match, so allow millimetres).
  Robot robot(withoutOdometry(), circlePath);
  std::vector<Pose2D> first;
  for (int i = 0; i <= 40; ++i) first.push_back(robot.step(0.1 * i).pose);
  int resets = 0;
  for (int i = 0; i <= 40; ++i) {
    const TrackerUpdate update = robot.step(0.1 * i);
    if (update.reset) ++resets;
    EXPECT_EQ(update.reset, i == 0) << describe(update);
    expectPoseNear(update.pose, first[i], 0.01, deg(0.2), "second pass, scan " + std::to_string(i));
  }
  EXPECT_EQ(resets, 1);
  ASSERT_EQ(robot.warnings().size(), 1u);
  EXPECT_NE(robot.warnings()[0].find("went back"), std::string::npos) << robot.warnings()[0];
}

TEST(Robustness, StampsJumpingForwardByMinutesContinueFromThePose) {
  // The scanner's clock is corrected by five minutes while the robot drives, no wheels: a forward gap of
  // any length continues from the current pose (the velocity is too old to extrapolate over it, so the
  // pose is kept and the scan searched in the preset's box), and the tracking goes on.
  Robot robot(withoutOdometry(), circlePath);
  for (int i = 0; i <= 10; ++i) robot.step(0.1 * i);
  const double offset = 300.0;
  TrackerUpdate update = robot.stepAt(1.1, 1.1 + offset);
  EXPECT_FALSE(update.reset) << describe(update);
  EXPECT_FALSE(update.fallback) << describe(update);
  EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kNone) << describe(update);
  for (int i = 12; i <= 30; ++i) {
    update = robot.stepAt(0.1 * i, 0.1 * i + offset);
    EXPECT_FALSE(update.reset) << describe(update);
    EXPECT_FALSE(update.fallback) << describe(update);
  }
  EXPECT_TRUE(robot.warnings().empty()) << robot.warnings().front();
  expectPoseNear(update.pose, robot.truth(3.0), 0.03, deg(0.5), "after the gap");
}

TEST(Robustness, ClockGoingBackASecondWhileMovingDropsScansAndNeverResets) {
  // The robot's clock steps back by 1 s (NTP, a restarted driver; less than reset_on_jump_back) while it
  // drives: scans and wheel odometry stamped before the newest ones are dropped (flagged, nothing
  // published) until the clock has caught up; then the odometry goes on from where it was, with the wheels
  // (whose samples across the step say the robot moved 1 s in 0.1 s: a jump the prediction replaces by
  // the velocity) and the scans to find the pose.
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry();
  for (int i = 0; i <= 30; ++i) robot.step(0.1 * i);
  robot.setStampOffset(-1.0);
  int stale = 0;
  TrackerUpdate update;
  for (int i = 31; i <= 60; ++i) {
    update = robot.step(0.1 * i);
    EXPECT_FALSE(update.reset) << describe(update);
    EXPECT_EQ(update.stale, !update.published) << describe(update);
    stale += update.stale;
  }
  EXPECT_EQ(stale, 9) << "the scans stamped 2.1 .. 2.9 s again (3.0 s again is not older)";
  EXPECT_EQ(robot.pipeline().inputCounts().stale_scans, 9u);
  EXPECT_GE(robot.pipeline().inputCounts().stale_odometry, 45u);
  expectPoseNear(update.pose, robot.truth(6.0), 0.05, deg(1.0), "after the clock caught up");
}

TEST(Robustness, AMillisecondOfBackwardJitterDropsTheScanAndNeverResets) {
  // A driver's jitter: every 7th scan is stamped 1 ms before the one ahead of it. It is dropped and
  // flagged, nothing is published for it, and the published poses stay continuous.
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry();
  Pose2D previous;
  int stale = 0;
  for (int i = 0; i <= 60; ++i) {
    const double t = 0.1 * i;
    const bool jitter = i > 0 && i % 7 == 0;
    const TrackerUpdate update = robot.stepAt(t, jitter ? 0.1 * (i - 1) - 0.001 : t);
    EXPECT_EQ(update.stale, jitter) << describe(update);
    EXPECT_FALSE(update.reset && i > 0) << describe(update);
    stale += update.stale;
    if (!update.published) continue;
    if (i > 0) {
      // At most the motion since the last published pose (0.5 m/s, a scan or two) and a centimetre.
      const Pose2D step = hglasm_test::relativeByHand(previous, update.pose);
      EXPECT_LT(std::hypot(step.x, step.y), 0.5 * 0.2 + 0.01) << describe(update);
    }
    previous = update.pose;
  }
  EXPECT_EQ(stale, 8);
  EXPECT_EQ(robot.pipeline().inputCounts().stale_scans, 8u);
  EXPECT_EQ(robot.pipeline().inputCounts().jumps_back, 0u);
  expectPoseNear(previous, robot.truth(6.0), 0.03, deg(0.5), "after the jitter");
}

/// The wheels' pose on circlePath: 1 % long, drifting 2 mrad per metre (0.5 m/s).
Pose2D slightlyWrongWheels(double t) {
  const Pose2D truth = circlePath(t);
  return hglasm_test::rawPose(1.01 * truth.x, 1.01 * truth.y,
                              hglasm_test::angleDiff(truth.theta + 0.001 * t, 0.0));
}

TEST(Robustness, ForwardGapsWhileTheWheelsMoveContinueWithinTheWheelsError) {
  // No scans for 61 s, then for 200 s (a logger paused, a laser restarted), while the robot drives on and
  // its wheels keep counting: the pose continues, predicted by the wheels across the gap, and the first
  // scan after it is no farther from the truth than the wheels' own estimate.
  for (const double gap : {61.0, 200.0}) {
    SCOPED_TRACE("gap " + std::to_string(gap) + " s");
    // Wheels that miscount 1 % of every distance, stated as such (odometry/noise/systematic): over a
    // 100 m pause that is a metre, which the prediction across the gap must admit.
    TrackerOptions options;
    options.motion.systematic = 0.01;
    Robot robot(options, circlePath);
    robot.enableOdometry();
    robot.setOdometryPath(slightlyWrongWheels);
    TrackerUpdate update;
    for (int i = 0; i <= 30; ++i) update = robot.step(0.1 * i);
    const double after = 3.0 + gap;
    const Pose2D wheel_estimate = hglasm_test::composeByHand(
        update.pose, hglasm_test::relativeByHand(slightlyWrongWheels(3.0), slightlyWrongWheels(after)));
    update = robot.step(after);
    EXPECT_FALSE(update.reset) << describe(update);
    EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry) << describe(update);
    const Pose2D truth = robot.truth(after);
    const double wheel_error = std::hypot(wheel_estimate.x - truth.x, wheel_estimate.y - truth.y);
    const double error = std::hypot(update.pose.x - truth.x, update.pose.y - truth.y);
    EXPECT_LE(error, std::max(wheel_error, 0.03)) << describe(update) << " wheels " << wheel_error;
    // Then it tracks on: the wheels, learned to be good before the gap, now err by a centimetre a step
    // (their heading is 0.2 rad off the direction they count along); the scans hold the pose far closer
    // than the wheels alone would.
    const Pose2D at_gap = update.pose;
    for (int i = 1; i <= 30; ++i) {
      update = robot.step(after + 0.1 * i);
      EXPECT_FALSE(update.reset) << describe(update);
      EXPECT_FALSE(update.fallback) << describe(update);
    }
    const Pose2D wheels_only = hglasm_test::composeByHand(
        at_gap, hglasm_test::relativeByHand(slightlyWrongWheels(after), slightlyWrongWheels(after + 3.0)));
    const Pose2D truth_after = robot.truth(after + 3.0);
    const double wheels_drift = std::hypot(wheels_only.x - truth_after.x, wheels_only.y - truth_after.y);
    expectPoseNear(update.pose, truth_after, std::min(0.1, 0.5 * wheels_drift), deg(1.0), "after the gap");
    EXPECT_TRUE(robot.warnings().empty()) << robot.warnings().front();
  }
}

TEST(Robustness, AClockJumpingBackAHundredSecondsResetsOnceWithAWarning) {
  // Scans and wheels both go back 100 s (a restarted clock, a looped bag): a new timeline. The odometry
  // restarts from the origin once, says why, forgets the wheels' samples of the old timeline, and tracks
  // on with the new ones.
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry();
  for (int i = 0; i <= 30; ++i) robot.step(0.1 * i);
  robot.setStampOffset(-100.0);
  TrackerUpdate update = robot.step(3.1);
  EXPECT_TRUE(update.reset) << describe(update);
  EXPECT_EQ(update.pose.x, 0.0);
  for (int i = 32; i <= 60; ++i) {
    update = robot.step(0.1 * i);
    EXPECT_FALSE(update.reset) << describe(update);
    EXPECT_FALSE(update.stale) << describe(update);
    EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry) << describe(update);
  }
  ASSERT_EQ(robot.warnings().size(), 1u) << robot.warnings().back();
  EXPECT_NE(robot.warnings()[0].find("went back by 99.9 s"), std::string::npos) << robot.warnings()[0];
  EXPECT_EQ(robot.pipeline().inputCounts().jumps_back, 1u);
  expectPoseNear(update.pose, hglasm_test::relativeByHand(robot.truth(3.1), robot.truth(6.0)), 0.03, deg(0.5),
                 "since the reset");
}

TEST(Robustness, ScansAlternatingBetween180And181BeamsAndFourStartAnglesNeedNoKeyframe) {
  // As fr-clinic's interleaving scanner: 180 or 181 beams of 1 degree, the first at one of four angles a
  // quarter degree apart. Keyframes come with the motion only (0.05 m per scan: one per 0.3 m).
  TrackerOptions options;
  options.keyframe.distance = 0.3;
  const auto path = [](double t) { return hglasm_test::rawPose(0.5 * t, 0.0, 0.0); };
  Robot robot(options, path);
  robot.enableOdometry();
  int keyframes = 0;
  TrackerUpdate update;
  for (int i = 0; i <= 40; ++i) {
    LaserSpec laser = hglasm_test::laserSpec(deg(180.0), 181);
    laser.angle_increment = deg(1.0);
    laser.beams = i % 3 == 0 ? 181 : 180;
    laser.angle_min = -hglasm_test::kPi / 2 + deg(0.25) * (i % 4);
    robot.setLaser(laser);
    update = robot.step(0.1 * i);
    keyframes += update.new_keyframe;
    EXPECT_FALSE(update.fallback) << describe(update);
  }
  EXPECT_LE(keyframes, 1 + 2.0 / 0.3 + 1) << "one per 0.3 m travelled";
  EXPECT_TRUE(robot.warnings().empty()) << robot.warnings().front();
  expectPoseNear(update.pose, path(4.0), 0.02, deg(0.3), "after 2 m");
}

// ------------------------------------------------------------------ wheel-odometry faults

TEST(Robustness, LateOdometryFallsBackToConstantVelocityAndIsFlagged) {
  // Odometry arrives 0.5 s late (a congested network): beyond max_odometry_extrapolation at every scan,
  // so the tracker must say it predicted with the constant velocity, and still track.
  TrackerOptions options;
  options.prediction.max_odometry_extrapolation = 0.25;
  Robot robot(options, circlePath);
  robot.enableOdometry();
  robot.setOdometryDelay(0.5);
  TrackerUpdate update;
  int constant_velocity = 0;
  for (int i = 0; i <= 50; ++i) {
    update = robot.step(0.1 * i);
    if (i == 0) continue;
    EXPECT_NE(update.diagnostics.prediction, PredictionSource::kOdometry) << describe(update);
    if (update.diagnostics.prediction == PredictionSource::kConstantVelocity) ++constant_velocity;
    EXPECT_FALSE(update.fallback) << describe(update);
  }
  EXPECT_GE(constant_velocity, 48);
  expectPoseNear(update.pose, robot.truth(5.0), 0.03, deg(0.5), "late odometry");
  // A moderate delay (within max_extrapolation) is bridged by extrapolating the odometry itself.
  Robot slightly_late(options, circlePath);
  slightly_late.enableOdometry();
  slightly_late.setOdometryDelay(0.1);
  for (int i = 0; i <= 30; ++i) {
    update = slightly_late.step(0.1 * i);
    if (i > 1) {  // at 0.1 s no sample is old enough yet
      EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry) << describe(update);
    }
  }
  expectPoseNear(update.pose, slightly_late.truth(3.0), 0.03, deg(0.5), "slightly late odometry");
}

TEST(Robustness, OdometryJumpingTenMetresHasABoundedEffectAndIsFlagged) {
  for (const Pose2D& jump : {Pose2D(10.0, 0.0, 0.0), Pose2D(0.0, -10.0, 0.0), Pose2D(7.0, 7.0, 2.0)}) {
    SCOPED_TRACE("jump " + std::to_string(jump.x) + " " + std::to_string(jump.y) + " " +
                 std::to_string(jump.theta));
    Robot robot(TrackerOptions(), circlePath);
    robot.enableOdometry(2.03, jump);  // the wheel-odometry frame is offset from 2.03 s on (a re-init)
    TrackerUpdate update;
    int flagged = 0;
    for (int i = 0; i <= 50; ++i) {
      update = robot.step(0.1 * i);
      if (i == 0) continue;
      EXPECT_FALSE(update.fallback) << describe(update);
      if (i == 21) {  // the step over the jump: odometry implausible, constant velocity, one warning
        EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kConstantVelocity) << describe(update);
        EXPECT_NE(update.warning.find("jumped"), std::string::npos) << describe(update);
        ++flagged;
      } else {
        EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry) << describe(update);
      }
      // Bounded: the estimate never leaves the true path.
      expectPoseNear(update.pose, robot.truth(0.1 * i), 0.03, deg(0.5), describe(update));
    }
    EXPECT_EQ(flagged, 1);
    EXPECT_EQ(robot.warnings().size(), 1u);
  }
}

TEST(Robustness, OdometrySpikeOfOneSampleHasABoundedEffect) {
  // One corrupt wheel-odometry sample 10 m away (a glitch). Scans fall between samples, so the
  // interpolated odometry carries a fraction of the spike: a large fraction is an implausible jump (constant
  // velocity instead, warned), a small one a guess that is off by up to ~0.7 m, which the pre-alignment box
  // of the medium preset (+-1 m) still covers.
  for (double fraction : {0.5, 0.05}) {
    SCOPED_TRACE("spike fraction " + std::to_string(fraction));
    OdometryTracker tracker{TrackerOptions()};
    const hglasm_test::World world = hglasm_test::room();
    const LaserSpec laser = hglasm_test::halfCircleLaser();
    int warnings = 0, deferred = 0;
    const double first_scan = 0.1 - 0.01 * (1.0 - fraction);
    for (int i = 0; i <= 300; ++i) {  // odometry at 100 Hz; scans at 10 Hz between two samples
      const double t = 0.01 * i;
      Pose2D odom = circlePath(t);
      if (i == 150) odom = hglasm_test::rawPose(odom.x + 10.0, odom.y, odom.theta);  // the spike
      tracker.addOdometry(t, odom);
      if (i % 10 != 0 || i == 0) continue;
      // The scan `fraction` of a sample period before this sample: after the spike at 1.50 s the scan at
      // 1.50 - 0.01 * (1 - fraction) s sees `fraction` of it.
      const double stamp = t - 0.01 * (1.0 - fraction);
      const TrackerUpdate update = tracker.processScan(
          stamp, hglasm::scanFromRanges(hglasm_test::simulateRanges(world, circlePath(stamp), laser)));
      expectSane(update);
      if (!update.warning.empty()) ++warnings;
      EXPECT_FALSE(update.fallback) << describe(update);
      // Wheels that have not been wrong before leap only once the next scan asks for the same correction:
      // the scan the spike reached keeps to the wheels (0.5 m off, flagged), the next is back on them.
      if (update.diagnostics.leap_deferred) {
        ++deferred;
        continue;
      }
      expectPoseNear(update.pose, hglasm_test::relativeByHand(circlePath(first_scan), circlePath(stamp)),
                     0.03, deg(0.5), describe(update));
    }
    // The two steps touching the spike warn when it is implausible; a small fraction passes silently.
    EXPECT_EQ(warnings, fraction > 0.1 ? 2 : 0);
    EXPECT_LE(deferred, 1);
  }
}

// ------------------------------------------------------------------ degenerate geometry

TEST(Robustness, FeaturelessCorridorIsUncertainAlongItAndDoesNotJump) {
  // Driving along a long featureless corridor with a short-range laser, with and without wheel odometry.
  const auto laser = hglasm_test::laserSpec(deg(270.0), 541, false, 8.0);
  for (bool with_odometry : {true, false}) {
    SCOPED_TRACE(with_odometry ? "with odometry" : "without odometry");
    TrackerOptions options = with_odometry ? TrackerOptions() : withoutOdometry();
    // The calibrated floor of unexplained error is the same in every direction; what is checked here is
    // what the scan and the wheels know.
    options.uncertainty.unexplained_xy = options.uncertainty.unexplained_theta = 0.0;
    Robot robot(options, arcPath(0.5, 0.0), laser, hglasm_test::corridor(1.0, 200.0));
    if (with_odometry) robot.enableOdometry();
    TrackerUpdate update, previous;
    for (int i = 0; i <= 60; ++i) {
      previous = update;
      update = robot.step(0.1 * i);
      if (i == 0) continue;
      // No jump: no step moves further than the robot could (0.05 m per scan) plus the GA's slack.
      const Pose2D step = hglasm_test::relativeByHand(previous.pose, update.pose);
      EXPECT_LT(std::hypot(step.x, step.y), 0.15) << describe(update);
      EXPECT_LT(std::abs(step.theta), deg(2.0)) << describe(update);
      // Across the corridor and in heading the scan determines the pose.
      EXPECT_NEAR(update.pose.y, 0.0, 0.02) << describe(update);
      EXPECT_NEAR(update.pose.theta, 0.0, deg(0.5)) << describe(update);
      // The covariance knows that the corridor direction is unobserved.
      EXPECT_GT(update.pose_covariance(0, 0), 10.0 * update.pose_covariance(1, 1)) << describe(update) << "\n"
                                                                                   << update.pose_covariance;
    }
    if (with_odometry) {
      // Along the corridor only the wheel odometry knows the motion: the estimate follows it.
      EXPECT_NEAR(update.pose.x, 3.0, 0.1) << describe(update);
    } else {
      // Without odometry nothing observes the motion along the corridor; it must stay bounded.
      EXPECT_LT(std::abs(update.pose.x), 6.0) << describe(update);
    }
  }
}

// ------------------------------------------------------------------ fusion: the prediction as a prior

TEST(Fusion, AWheelSlipTheScansContradictIsOverruledAsALeap) {
  // From 2.03 s on the wheel odometry is 0.3 m off sideways (a slip; small enough to pass as plausible
  // motion): the scans in the room say otherwise, and the estimate must follow them, flagged as a leap. The
  // wheels have not been wrong before: the first scan past the slip defers the leap, the next asks for the
  // same correction and takes it.
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry(2.03, Pose2D(0.0, 0.3, 0.0));
  int leaps = 0, deferred = 0;
  for (int i = 0; i <= 50; ++i) {
    const TrackerUpdate update = robot.step(0.1 * i);
    if (i == 0) continue;
    EXPECT_FALSE(update.fallback) << describe(update);
    EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry) << describe(update);
    leaps += update.leap;
    if (update.diagnostics.leap_deferred) {
      EXPECT_EQ(i, 21) << "the first scan past the slip";
      ++deferred;
      continue;
    }
    expectPoseNear(update.pose, robot.truth(0.1 * i), 0.03, deg(0.5), describe(update));
  }
  EXPECT_EQ(deferred, 1);
  EXPECT_GE(leaps, 1) << "the step after the slip";
  EXPECT_LE(leaps, 2) << "afterwards the wheels' increments are right again";
}

TEST(Fusion, DownAFeaturelessCorridorTheFusedDistanceIsUnbiased) {
  // 1 m per scan down a corridor whose walls say nothing about the distance, with wheels whose distance
  // and heading wander by a known small noise (a random walk, seeded): the fused motion along the corridor
  // must be the wheels' (no pull towards "no motion" from a map of the scans just before), unbiased to
  // 1 % of the distance, while across the corridor and in heading the walls correct the wheels.
  const auto laser = hglasm_test::laserSpec(deg(270.0), 541, false, 8.0);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::vector<Pose2D> wheels;  // every 0.02 s over 41 s
  double along = 0.0, across = 0.0, heading = 0.0;
  for (int k = 0; k <= 2050; ++k) {
    wheels.push_back(hglasm_test::rawPose(along, across, heading));
    along += 0.02 * (1.0 + 0.1 * normal(rng));  // 1 m/s, 1.4 cm of distance noise per metre
    heading += 0.0005 * normal(rng);            // 3.5 mrad per metre
    across += 0.02 * std::sin(heading);
  }
  const Path noisy_wheels = [&wheels](double t) {
    return wheels[std::min<std::size_t>(wheels.size() - 1, static_cast<std::size_t>(std::lround(t / 0.02)))];
  };
  Robot robot(TrackerOptions(), arcPath(1.0, 0.0), laser, hglasm_test::corridor(1.0, 200.0));
  robot.enableOdometry();
  robot.setOdometryPath(noisy_wheels);
  TrackerUpdate previous = robot.step(0.0), update;
  double along_error = 0.0, worst_across = 0.0, worst_heading = 0.0;
  int steps = 0;
  for (int i = 1; i <= 40; ++i) {  // one scan a second
    update = robot.step(1.0 * i);
    ASSERT_FALSE(update.fallback) << describe(update);
    along_error += hglasm_test::relativeByHand(previous.pose, update.pose).x - 1.0;
    worst_across = std::max(worst_across, std::abs(update.pose.y));
    worst_heading = std::max(worst_heading, std::abs(update.pose.theta));
    previous = update;
    ++steps;
  }
  const double wheels_heading = std::abs(noisy_wheels(40.0).theta);
  EXPECT_LT(std::abs(along_error / steps), 0.01) << "mean error along the corridor per metre travelled";
  EXPECT_NEAR(update.pose.x, noisy_wheels(40.0).x, 0.02) << "along the corridor the wheels decide";
  EXPECT_LT(worst_across, 0.03) << "across the corridor the walls decide";
  EXPECT_LT(worst_heading, deg(0.5)) << "and in heading (the wheels end " << wheels_heading << " rad off)";
  EXPECT_GT(wheels_heading, 2.0 * worst_heading) << "the scenario must test the walls";
  // What the scene constrains is reported: nothing along the corridor.
  EXPECT_LT(update.diagnostics.degeneracy, 1e-3) << describe(update);
  EXPECT_GT(std::abs(update.diagnostics.weakest_direction.x()), 0.95)
      << update.diagnostics.weakest_direction.transpose();
}

TEST(Fusion, InACorridorTheWallsGiveTheHeadingAndTheWheelsTheDistance) {
  // Straight along a featureless corridor while the wheels believe they turn at 0.05 rad/s (17 degrees
  // in 6 s). Fused, the scans fix heading and side offset and the wheels the distance travelled; a match
  // that replaces the wheels cannot see the distance, fails, and integrates the drifting wheels instead.
  const auto laser = hglasm_test::laserSpec(deg(270.0), 541, false, 8.0);
  const auto drive = [&](bool fusion) {
    TrackerOptions options;
    options.fusion = fusion;
    Robot robot(options, arcPath(0.5, 0.0), laser, hglasm_test::corridor(1.0, 200.0));
    robot.enableOdometry();
    robot.setOdometryPath(arcPath(0.5, 0.05));
    TrackerUpdate update;
    for (int i = 0; i <= 60; ++i) update = robot.step(0.1 * i);
    return update;
  };
  const TrackerUpdate fused = drive(true);
  EXPECT_NEAR(fused.pose.y, 0.0, 0.02) << describe(fused);
  EXPECT_NEAR(fused.pose.theta, 0.0, deg(0.5)) << describe(fused);
  EXPECT_NEAR(fused.pose.x, 3.0, 0.1) << describe(fused) << ": the wheels' distance";
  const TrackerUpdate replaced = drive(false);
  EXPECT_GT(std::abs(replaced.pose.theta), deg(10.0)) << describe(replaced);
}

/// Clockwise circle of radius 1.5 m at 0.5 m/s, as wheels that over-report the turn rate by `factor` see it.
Path miscalibratedCircle(double factor) {
  return [factor](double t) {
    const double radius = 1.5 / factor, rate = 0.5 / radius;
    return hglasm_test::rawPose(radius * std::sin(rate * t), -radius + radius * std::cos(rate * t),
                                hglasm_test::angleDiff(-rate * t, 0.0));
  };
}

/// Drives the circle with wheels that over-report turning by `factor`; the estimate must follow the scans.
hglasm::LearnedModels learnedOnTheCircle(double factor, bool calibrate) {
  TrackerOptions options;
  options.learning.wheel_calibration.learn = calibrate;
  Robot robot(options, circlePath);
  robot.enableOdometry();
  robot.setOdometryPath(miscalibratedCircle(factor));
  TrackerUpdate update;
  for (int i = 0; i <= 300; ++i) {
    update = robot.step(0.1 * i);
    expectPoseNear(update.pose, robot.truth(0.1 * i), 0.03, deg(0.5), describe(update));
  }
  return update.diagnostics.learned;
}

TEST(Fusion, TheWheelsNoiseIsLearnedFromTheScans) {
  // Without the turn calibration, exact wheels teach a small heading-noise scale and wheels that over-report
  // turning by half a large one.
  const hglasm::MotionNoiseScale exact = learnedOnTheCircle(1.0, false).wheel_noise;
  const hglasm::MotionNoiseScale bad = learnedOnTheCircle(1.5, false).wheel_noise;
  EXPECT_LT(exact.theta, 0.1);
  EXPECT_GT(bad.theta, 1.0);
  EXPECT_GT(bad.theta, 20.0 * exact.theta);
}

TEST(Fusion, AWrongWheelBaseIsCalibratedAwayNotLearnedAsNoise) {
  // By default the turn scale is learned: wheels over-reporting turns by half (true = wheels * (1 - 1/3))
  // are corrected, and what is left of their heading noise is as small as exact wheels'.
  const hglasm::LearnedModels exact = learnedOnTheCircle(1.0, true);
  const hglasm::LearnedModels bad = learnedOnTheCircle(1.5, true);
  EXPECT_NEAR(exact.wheel_turn_scale, 0.0, 0.01);
  EXPECT_NEAR(bad.wheel_turn_scale, 1.0 / 1.5 - 1.0, 0.02);
  EXPECT_LT(bad.wheel_noise.theta, 0.1);
}

}  // namespace
