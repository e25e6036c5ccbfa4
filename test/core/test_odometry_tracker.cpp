// Laser odometry on a simulated robot: known paths with and without wheel odometry, keyframe policy,
// laser mounting, time going backwards or jumping, duplicate stamps, and empty scans.
#include "hglasm_odometry/core/odometry_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <utility>

#include "simulated_robot.h"
#include "test_expect.h"
#include "test_util.h"

namespace {

using hglasm::OdometryTracker;
using hglasm::Pose2D;
using hglasm::PredictionSource;
using hglasm::TrackerOptions;
using hglasm::TrackerUpdate;

using hglasm_test::kPi;
using hglasm_test::Path;

/// Clockwise circle of radius 1.5 m through the origin at 0.5 m/s, starting at the identity pose; it stays
/// clear of the room's boxes and walls.
Pose2D circlePath(double t) {
  const double radius = 1.5, rate = 0.5 / radius;
  return hglasm_test::rawPose(radius * std::sin(rate * t), -radius + radius * std::cos(rate * t),
                              hglasm_test::angleDiff(-rate * t, 0.0));
}

/// Straight along +x at `speed` m/s from the origin.
Path straightPath(double speed) {
  return [speed](double t) { return hglasm_test::rawPose(speed * t, 0.0, 0.0); };
}

/// Turning on the spot at `rate` rad/s.
Path spinPath(double rate) {
  return [rate](double t) { return hglasm_test::rawPose(0.0, 0.0, hglasm_test::angleDiff(rate * t, 0.0)); };
}

void expectSane(const TrackerUpdate& update) {
  EXPECT_TRUE(update.pose.isFinite()) << "stamp " << update.stamp;
  EXPECT_TRUE(update.diagnostics.guess.isFinite()) << "stamp " << update.stamp;
  EXPECT_TRUE(update.velocity.allFinite()) << "stamp " << update.stamp;
  EXPECT_TRUE(hglasm_test::isValidCovariance(update.pose_covariance)) << update.pose_covariance;
  EXPECT_TRUE(hglasm_test::isValidCovariance(update.velocity_covariance)) << update.velocity_covariance;
  EXPECT_TRUE(update.diagnostics.match.pose.isFinite());
  EXPECT_TRUE(update.diagnostics.match.covariance.allFinite());
}

/// The simulated robot (simulated_robot.h) feeding an OdometryTracker: its wheel and gyro samples up to
/// each scan, then the scan.
class Robot {
 public:
  Robot(const TrackerOptions& options, Path path) : tracker_(options), sim_(std::move(path)) {
    sim_.setMount(Pose2D());  // these scans always went through the mount, the identity included
  }

  void setMount(const Pose2D& mount) { setMounts(mount, mount); }
  /// The laser truly at `truth`, tf stating `stated`.
  void setMounts(const Pose2D& truth, const Pose2D& stated) {
    sim_.setMount(truth);
    tracker_.setLaserMount(stated);
  }

  /// Wheel odometry with a scale error and a heading drift (integrated from the true motion), that counts
  /// `turn_scale` of every turn (a skid-steer robot's wheels slip as it turns).
  void enableOdometry(double scale_error, double drift_per_metre, double turn_scale = 1.0) {
    sim_.enableWheels();
    sim_.wheels().setErrors(scale_error, drift_per_metre, turn_scale);
  }

  /// A gyro at 200 Hz: the true yaw rate plus a constant `bias` (rad/s) and white noise of
  /// `noise_density` (rad/s per sqrt(Hz)), from a seeded generator.
  void enableGyro(double bias, double noise_density, unsigned seed) {
    hglasm_test::GyroSpec gyro;
    gyro.bias = bias;
    gyro.noise_density = noise_density;
    gyro.seed = seed;
    sim_.enableGyro(gyro);
  }
  void disableGyro() { sim_.disableGyro(); }

  Pose2D truth(double t) const { return sim_.truth(t); }
  Pose2D odometryPose() const { return sim_.wheels().pose(); }

  /// A laser whose sweep lasts `seconds` from the first beam to the last (0: all beams at once).
  void setSweepTime(double seconds) { sim_.setSweepTime(seconds); }
  hglasm::Scan scanAt(double t) const { return sim_.scanAt(t); }

  /// Advances to time t: the wheels up to t and the gyro to the end of the sweep, then one scan at t (or
  /// `scan` if given).
  TrackerUpdate step(double t, const hglasm::Scan* scan = nullptr) {
    hglasm_test::RobotSink sink;
    sink.wheels = [this](double stamp, const Pose2D& pose) { tracker_.addOdometry(stamp, pose); };
    sink.gyro = [this](double stamp, double yaw_rate) { tracker_.addImu(stamp, yaw_rate); };
    sim_.advanceTo(t, sink);
    return tracker_.processScan(t, scan ? *scan : sim_.scanAt(t));
  }

  OdometryTracker& tracker() { return tracker_; }

 private:
  OdometryTracker tracker_;
  hglasm_test::SimulatedRobot sim_;
};

TrackerOptions withoutOdometry() {
  TrackerOptions options;
  options.prediction.use_odometry = false;
  return options;
}

TEST(OdometryTracker, FirstScanIsPublishedAtTheOrigin) {
  Robot robot(TrackerOptions(), circlePath);
  const TrackerUpdate first = robot.step(0.0);
  expectSane(first);
  EXPECT_TRUE(first.published);
  EXPECT_FALSE(first.matched);
  EXPECT_TRUE(first.new_keyframe);
  EXPECT_EQ(first.pose.x, 0.0);
  EXPECT_EQ(first.pose.y, 0.0);
  EXPECT_EQ(first.pose.theta, 0.0);
  // No velocity is known yet: its covariance says so (not an identity that claims 1 m/s).
  EXPECT_EQ(first.velocity_covariance, Eigen::Matrix3d::Identity() * hglasm::kUnknownVariance);
}

TEST(OdometryTracker, AfterAResetTheVelocityIsUnknownAgain) {
  Robot robot(TrackerOptions(), circlePath);
  TrackerUpdate update;
  for (int i = 0; i <= 10; ++i) update = robot.step(0.1 * i);
  EXPECT_LT(update.velocity_covariance(0, 0), 1.0) << "a second of motion: the velocity is known";
  robot.tracker().reset();
  update = robot.step(1.1);
  EXPECT_TRUE(update.reset);
  EXPECT_EQ(update.velocity_covariance, Eigen::Matrix3d::Identity() * hglasm::kUnknownVariance);
}

/// Drives `seconds` at 10 Hz; returns the final update. Every update must be sane and matched.
TrackerUpdate drive(Robot* robot, double seconds, int* fallbacks, int* keyframes) {
  TrackerUpdate update;
  *fallbacks = 0;
  *keyframes = 0;
  for (int i = 0; i <= static_cast<int>(std::lround(seconds * 10.0)); ++i) {
    update = robot->step(0.1 * i);
    expectSane(update);
    EXPECT_TRUE(update.published);
    if (i > 0) {
      EXPECT_TRUE(update.matched) << "scan " << i;
      if (update.fallback) ++*fallbacks;
      if (update.new_keyframe) ++*keyframes;
    }
  }
  return update;
}

TEST(OdometryTracker, FollowsACircleWithoutWheelOdometry) {
  Robot robot(withoutOdometry(), circlePath);
  int fallbacks = 0, keyframes = 0;
  const TrackerUpdate last = drive(&robot, 25.0, &fallbacks, &keyframes);  // 12.5 m, 5/6 of a turn
  const Pose2D truth = robot.truth(25.0);
  EXPECT_EQ(fallbacks, 0);
  EXPECT_GT(keyframes, 10);
  EXPECT_EQ(last.diagnostics.prediction, PredictionSource::kConstantVelocity);
  hglasm_test::expectPoseNear(last.pose, truth, 0.05, hglasm_test::deg(0.5), "final pose");
  // The velocity is the path's: 0.5 m/s forward, turning right at 1/3 rad/s.
  EXPECT_NEAR(last.velocity.x(), 0.5, 0.05);
  EXPECT_NEAR(last.velocity.y(), 0.0, 0.05);
  EXPECT_NEAR(last.velocity.z(), -1.0 / 3.0, 0.05);
}

TEST(OdometryTracker, FollowsACircleWithDriftingWheelOdometry) {
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry(0.05, 0.03);  // 5 % scale error, 0.03 rad of heading drift per metre
  int fallbacks = 0, keyframes = 0;
  const TrackerUpdate last = drive(&robot, 25.0, &fallbacks, &keyframes);
  const Pose2D truth = robot.truth(25.0);
  EXPECT_EQ(fallbacks, 0);
  EXPECT_EQ(last.diagnostics.prediction, PredictionSource::kOdometry);
  hglasm_test::expectPoseNear(last.pose, truth, 0.05, hglasm_test::deg(0.5), "final pose");
  // The wheel odometry alone is far off: the laser did the work.
  EXPECT_GT(hglasm_test::translationError(robot.odometryPose(), truth), 0.3);
}

TEST(OdometryTracker, ThePublishedFitnessIsTheGradedTablesAtThePublishedPose) {
  // The published fitness (and min_fitness) is the fine graded table's at the published pose.
  TrackerOptions options;
  Robot robot(options, circlePath);
  robot.enableOdometry(0.02, 0.01);
  int fallbacks = 0, keyframes = 0;
  const TrackerUpdate last = drive(&robot, 3.0, &fallbacks, &keyframes);
  EXPECT_EQ(fallbacks, 0);
  hglasm_test::expectPoseNear(last.pose, robot.truth(3.0), 0.03, hglasm_test::deg(0.5), "final pose");
  // A simulated scan on its own map at the right pose: nearly every point on a surface.
  EXPECT_GT(last.diagnostics.fitness_ratio, 0.8);
  EXPECT_LE(last.diagnostics.fitness_ratio, 1.0);
}

TEST(OdometryTracker, AFailedMatchPublishesTheFitnessAtThePredictedPose) {
  TrackerOptions options;
  options.min_fitness = 1.0;  // no match is good enough: every scan integrates the wheels
  Robot robot(options, circlePath);
  robot.enableOdometry(0.0, 0.0);  // exact wheels: the predicted pose is the true one
  robot.step(0.0);
  const TrackerUpdate update = robot.step(0.1);
  EXPECT_TRUE(update.matched);
  EXPECT_TRUE(update.fallback);
  EXPECT_GT(update.diagnostics.fitness_ratio, 0.8);
  EXPECT_LT(update.diagnostics.fitness_ratio, 1.0);
}

TEST(OdometryTracker, LaserMountIsAccountedFor) {
  Robot robot(withoutOdometry(), circlePath);
  robot.setMount(Pose2D(0.3, 0.1, 0.2));
  int fallbacks = 0, keyframes = 0;
  const TrackerUpdate last = drive(&robot, 10.0, &fallbacks, &keyframes);
  const Pose2D truth = robot.truth(10.0);  // the base, not the laser
  EXPECT_EQ(fallbacks, 0);
  hglasm_test::expectPoseNear(last.pose, truth, 0.03, hglasm_test::deg(0.5), "final pose");
}

/// Exact wheels on the circle, the laser truly 15 cm ahead of where tf states it (`laser_offset` 0: the
/// stated mount is taken as exact). Returns the last update; the published frame is tf's (the laser's pose
/// composed with the stated mount's inverse), from the origin where the tracker started it.
TrackerUpdate driveWithAWrongMount(double laser_offset, Pose2D* published_truth, Pose2D* mount_in_use,
                                   double* largest_step_error, double* largest_mount_change = nullptr) {
  TrackerOptions options;
  options.learning.wheel_calibration.laser_offset = laser_offset;
  Robot robot(options, circlePath);
  const Pose2D stated(0.1, 0.0, 0.0), truth(0.25, 0.0, 0.0);
  robot.setMounts(truth, stated);
  robot.enableOdometry(0.0, 0.0);
  const auto published = [&](double t) { return robot.truth(t) * truth * stated.inverse(); };
  TrackerUpdate last, previous;
  *largest_step_error = 0.0;
  double mount_change = 0.0;
  for (int i = 0; i <= 250; ++i) {
    const Pose2D mount_before = robot.tracker().mountInUse();
    last = robot.step(0.1 * i);
    mount_change =
        std::max(mount_change, relativePose(mount_before, robot.tracker().mountInUse()).translationNorm());
    expectSane(last);
    EXPECT_FALSE(last.fallback) << "scan " << i;
    if (i > 0) {
      // Each published step against the true step of tf's frame.
      const Pose2D error = relativePose(relativePose(published(0.1 * (i - 1)), published(0.1 * i)),
                                        relativePose(previous.pose, last.pose));
      *largest_step_error = std::max(*largest_step_error, error.translationNorm());
    }
    previous = last;
  }
  *published_truth = published(0.0).inverse() * published(25.0);
  *mount_in_use = robot.tracker().mountInUse();
  if (largest_mount_change) *largest_mount_change = mount_change;
  return last;
}

TEST(OdometryTracker, LearnsWhereTheLaserSitsWhenTheMountIsWrong) {
  Pose2D published_truth, mount;
  double step_error = 0.0, mount_change = 0.0;
  const TrackerUpdate learned =
      driveWithAWrongMount(0.1, &published_truth, &mount, &step_error, &mount_change);
  // The learned place moves up to a centimetre per scan here; the mount in use 1 mm at most, so that
  // odom -> base_link does not leap.
  EXPECT_LE(mount_change, 0.001 + 1e-12);
  EXPECT_LT(step_error, 0.004);
  EXPECT_NEAR(learned.diagnostics.learned.laser_offset.x(), 0.15, 0.02);
  EXPECT_NEAR(learned.diagnostics.learned.laser_offset.y(), 0.0, 0.02);
  hglasm_test::expectPoseNear(mount, Pose2D(0.25, 0.0, 0.0), 0.02, 1e-12, "the mount in use");
  hglasm_test::expectPoseNear(learned.pose, published_truth, 0.03, hglasm_test::deg(0.5), "learned mount");
  EXPECT_LT(learned.diagnostics.learned.wheel_noise.xy, 0.01) << "exact wheels are learned as exact";
  // Taken as exact, the wrong lever arm moves the wheels' motion where the laser's is not: in every turn
  // the exact wheels look wrong sideways, and are learned as noisy (the fusion then trusts them less).
  const TrackerUpdate stated = driveWithAWrongMount(0.0, &published_truth, &mount, &step_error);
  EXPECT_EQ(stated.diagnostics.learned.laser_offset.norm(), 0.0);
  EXPECT_EQ(mount.x, 0.1);
  EXPECT_GT(stated.diagnostics.learned.wheel_noise.xy, 0.05);
  hglasm_test::expectPoseNear(stated.pose, published_truth, 0.03, hglasm_test::deg(0.5), "stated mount");
  EXPECT_EQ(TrackerOptions().learning.wheel_calibration.laser_offset, 0.0) << "tf's mount by default";
}

TEST(OdometryTracker, DeskewUndoesTheShearOfASweepTakenWhileMoving) {
  // A slow laser (100 ms from the first beam to the last, like a Hokuyo URG), mounted off-centre on the
  // robot driving the circle: each sweep is sheared by 5 cm and 1.9 degrees. Compared: the motion from
  // 6 s to 20 s. The first keyframes are taken before there is a velocity to de-skew them with; a local
  // map of 5 to 8 keyframes forgets them within 5 s.
  const auto drive_swept = [](bool deskew, int* deskewed) {
    TrackerOptions options = withoutOdometry();
    options.deskew = deskew;
    options.local_map.keyframes = 4;  // the un-de-skewed first keyframes leave the map within 5 s
    Robot robot(options, circlePath);
    robot.setMount(Pose2D(0.3, 0.1, 0.2));
    robot.setSweepTime(0.1);
    int fallbacks = 0;
    *deskewed = 0;
    Pose2D at_six_seconds, last;
    for (int i = 0; i <= 200; ++i) {  // 20 s at 10 Hz: 10 m, 2/3 of a turn
      const TrackerUpdate update = robot.step(0.1 * i);
      expectSane(update);
      if (update.fallback) ++fallbacks;
      if (update.diagnostics.deskewed) ++*deskewed;
      if (i == 60) at_six_seconds = update.pose;
      last = update.pose;
    }
    EXPECT_EQ(fallbacks, 0);
    return std::make_pair(hglasm::relativePose(at_six_seconds, last),
                          hglasm::relativePose(robot.truth(6.0), robot.truth(20.0)));
  };
  int deskewed = 0;
  const auto [compensated, truth] = drive_swept(true, &deskewed);
  EXPECT_GE(deskewed, 198);  // all but the first two scans (no velocity yet)
  hglasm_test::expectPoseNear(compensated, truth, 0.01, hglasm_test::deg(0.1),
                              "de-skewed");  // 3 mm, 0.01 deg
  const auto [sheared, same_truth] = drive_swept(false, &deskewed);
  EXPECT_EQ(deskewed, 0);
  // What it undoes (more than 5 cm and 2 degrees here).
  EXPECT_GT(hglasm_test::translationError(sheared, same_truth), 0.05);
  EXPECT_GT(hglasm_test::rotationError(sheared, same_truth), hglasm_test::deg(2.0));
}

TEST(OdometryTracker, KeyframesFollowKeyframeDistance) {
  TrackerOptions options = withoutOdometry();
  options.keyframe.distance = 0.30;
  options.keyframe.angle = 10.0;
  Robot robot(options, straightPath(0.4));  // 0.04 m per scan
  int keyframes = 0;
  for (int i = 1; i <= 40; ++i) {  // 1.6 m: a new keyframe past every 0.30 m, i.e. every 8 scans
    const TrackerUpdate update = robot.step(0.1 * i);
    if (i == 1) continue;
    expectSane(update);
    EXPECT_FALSE(update.fallback) << i;
    if (update.new_keyframe) {
      ++keyframes;
      EXPECT_EQ(i % 8, 1) << "keyframe at scan " << i;  // moved 0.32 m since the last one
    }
  }
  EXPECT_EQ(keyframes, 4);
}

TEST(OdometryTracker, KeyframesFollowKeyframeAngle) {
  TrackerOptions options = withoutOdometry();
  options.keyframe.distance = 100.0;
  options.keyframe.angle = 0.20;
  Robot robot(options, spinPath(0.3));  // 0.03 rad per scan
  int keyframes = 0;
  const int first_keyframe = robot.step(0.0).keyframe_id;
  for (int i = 1; i <= 42; ++i) {  // a new keyframe past every 0.2 rad, i.e. every 7 scans
    const TrackerUpdate update = robot.step(0.1 * i);
    expectSane(update);
    EXPECT_FALSE(update.fallback) << i;
    if (update.new_keyframe) {
      ++keyframes;
      EXPECT_EQ(i % 7, 0) << "keyframe at scan " << i;
    }
  }
  EXPECT_EQ(keyframes, 6);
  EXPECT_EQ(robot.tracker().keyframeId(), first_keyframe + 6);
  EXPECT_NEAR(hglasm_test::angleDiff(robot.tracker().pose().theta, 0.3 * 4.2), 0.0, hglasm_test::deg(0.2));
}

TEST(OdometryTracker, AScanStampedBeforeTheLastOneIsNotProcessed) {
  // The tracker processes scans in stamp order (OdometryPipeline drops older ones, or restarts on a clock
  // that jumped back): one handed to it out of order changes nothing.
  Robot robot(withoutOdometry(), straightPath(0.4));
  for (int i = 0; i <= 10; ++i) robot.step(0.1 * i);
  const Pose2D before = robot.tracker().pose();
  const TrackerUpdate back = robot.step(0.5);
  EXPECT_TRUE(back.stale);
  EXPECT_FALSE(back.published);
  EXPECT_FALSE(back.reset);
  EXPECT_FALSE(back.warning.empty());
  EXPECT_EQ(robot.tracker().pose().x, before.x);
  TrackerUpdate update;
  for (int i = 11; i <= 15; ++i) {
    update = robot.step(0.1 * i);
    expectSane(update);
    EXPECT_FALSE(update.stale) << i;
    EXPECT_FALSE(update.fallback) << i;
  }
  EXPECT_NEAR(update.pose.x, 0.4 * 1.5, 0.01);
}

TEST(OdometryTracker, AForwardGapContinuesFromThePose) {
  // Ten minutes without scans while the wheels publish (the robot stood, then moves on): the odometry
  // continues from where it was, predicted by the wheels across the gap; nothing restarts.
  const Path stop_and_go = [](double t) {
    return hglasm_test::rawPose(0.4 * std::min(t, 0.5) + 0.4 * std::max(0.0, t - 600.5), 0.0, 0.0);
  };
  Robot robot(TrackerOptions(), stop_and_go);
  robot.enableOdometry(0.0, 0.0);
  for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
  const TrackerUpdate gap = robot.step(0.6 + 600.0);
  expectSane(gap);
  EXPECT_FALSE(gap.reset);
  EXPECT_FALSE(gap.fallback);
  EXPECT_EQ(gap.diagnostics.prediction, hglasm::PredictionSource::kOdometry);
  EXPECT_NEAR(gap.pose.x, stop_and_go(600.6).x, 0.01);
  const TrackerUpdate next = robot.step(0.7 + 600.0);
  expectSane(next);
  EXPECT_FALSE(next.reset);
}

TEST(OdometryTracker, DuplicateStampsNeverGiveNaN) {
  for (bool with_odometry : {false, true}) {
    SCOPED_TRACE(with_odometry ? "with odometry" : "without odometry");
    Robot robot(with_odometry ? TrackerOptions() : withoutOdometry(), straightPath(0.4));
    if (with_odometry) robot.enableOdometry(0.0, 0.0);
    for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
    const hglasm::Scan same = robot.scanAt(0.5);
    const hglasm::Scan later = robot.scanAt(0.52);
    const TrackerUpdate duplicate = robot.tracker().processScan(0.5, same);
    expectSane(duplicate);
    EXPECT_FALSE(duplicate.reset);
    const TrackerUpdate moved_same_stamp = robot.tracker().processScan(0.5, later);
    expectSane(moved_same_stamp);
    const TrackerUpdate tiny_dt = robot.tracker().processScan(0.5 + 1e-7, later);
    expectSane(tiny_dt);
    // Carrying on is still fine.
    TrackerUpdate update;
    for (int i = 6; i <= 12; ++i) {
      update = robot.step(0.1 * i);
      expectSane(update);
    }
    EXPECT_NEAR(update.pose.x, 0.4 * 1.2, 0.02);
    EXPECT_NEAR(update.velocity.x(), 0.4, 0.05);
  }
}

TEST(OdometryTracker, EmptyScansFallBackToTheOdometryGuess) {
  Robot robot(TrackerOptions(), circlePath);
  robot.enableOdometry(0.0, 0.0);  // exact wheel odometry: the fallback must follow it
  for (int i = 0; i <= 20; ++i) robot.step(0.1 * i);
  const hglasm::Scan empty;
  for (int i = 21; i <= 25; ++i) {
    const TrackerUpdate update = robot.step(0.1 * i, &empty);
    expectSane(update);
    EXPECT_TRUE(update.published) << i;
    EXPECT_TRUE(update.fallback) << i;
    EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry);
    const Pose2D truth = robot.truth(0.1 * i);
    EXPECT_LT(hglasm_test::translationError(update.pose, truth), 0.01) << i;
    EXPECT_LT(hglasm_test::rotationError(update.pose, truth), hglasm_test::deg(0.2)) << i;
  }
  // The uncertainty grew during the fallback, and tracking resumes with real scans.
  TrackerUpdate update;
  for (int i = 26; i <= 40; ++i) {
    update = robot.step(0.1 * i);
    expectSane(update);
    EXPECT_FALSE(update.fallback) << i;
  }
  EXPECT_LT(hglasm_test::translationError(update.pose, robot.truth(4.0)), 0.02);
}

TEST(OdometryTracker, AVelocitysGuessNoScanConfirmedDoesNotAnchorTheWheels) {
  // Turning in place at 1 rad/s for a second, then standing still; the wheels stall for 0.3 s just as the
  // turn ends (intel's late wheels), so a scan there is predicted at the turn's constant velocity, 0.3 rad
  // past where the robot stopped, and it cannot be matched. Once the wheels catch up they predict the
  // next scan from the last matched pose, not from the guess.
  Robot robot(TrackerOptions(), [](double t) { return Pose2D(0.0, 0.0, std::min(t, 1.0)); });
  robot.enableOdometry(0.0, 0.0);
  for (int i = 0; i <= 10; ++i) EXPECT_FALSE(robot.step(0.1 * i).fallback) << i;
  const hglasm::Scan empty;
  const TrackerUpdate guessed = robot.tracker().processScan(1.3, empty);  // the wheels end at 1.0
  EXPECT_TRUE(guessed.fallback);
  EXPECT_EQ(guessed.diagnostics.prediction, PredictionSource::kConstantVelocity);
  EXPECT_GT(hglasm_test::rotationError(guessed.pose, robot.truth(1.3)), 0.2) << "the velocity's guess";
  const TrackerUpdate next = robot.step(1.4);
  expectSane(next);
  EXPECT_EQ(next.diagnostics.prediction, PredictionSource::kOdometry);
  hglasm_test::expectPoseNear(next.diagnostics.guess, robot.truth(1.4), 0.005, hglasm_test::deg(0.5),
                              "the wheels' prediction");
  EXPECT_FALSE(next.fallback);
  EXPECT_FALSE(next.leap);
  hglasm_test::expectPoseNear(next.pose, robot.truth(1.4), 0.02, hglasm_test::deg(0.5), "the match");
}

/// Mean translation error over 3 s to 30 s of the circle, with wheels that slip by up to `size` (m on each
/// axis, rad) every `every` scans from 2 s on (a seeded draw), the tracker's options `options`.
double meanErrorWithSlips(const TrackerOptions& options, double size, int every) {
  Robot robot(options, circlePath);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> draw(-1.0, 1.0);
  Pose2D slip;  // what the wheels have lost so far, in their frame
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i <= 300; ++i) {
    const double t = 0.1 * i;
    if (i > 20 && i % every == 0)
      slip = Pose2D(size * draw(random), size * draw(random), size * draw(random)) * slip;
    for (int j = i > 0 ? 8 : 0; j >= 0; --j) {  // wheels at 100 Hz up to the scan
      robot.tracker().addOdometry(t - 0.01 * j, slip * robot.truth(t - 0.01 * j));
    }
    const TrackerUpdate update = robot.tracker().processScan(t, robot.scanAt(t));
    expectSane(update);
    if (i > 30) {
      sum += hglasm_test::translationError(update.pose, robot.truth(t));
      ++count;
    }
  }
  return sum / count;
}

TEST(OdometryTracker, WheelsThatSlipNowAndThenAreCorrectedNotCarriedOn) {
  // Each slip is a few sigma of the wheels' learned noise: too small for a leap, large enough that a prior
  // this tight would hold the match near it and pass it on. The slip mixture gives those scans to the scan.
  for (const double size : {0.02, 0.04, 0.08}) {
    for (const int every : {5, 20}) {
      SCOPED_TRACE("slips up to " + std::to_string(size) + " every " + std::to_string(every) + " scans");
      TrackerOptions options;
      const double with_mixture = meanErrorWithSlips(options, size, every);
      options.leap.slip_variance_scale = 0.0;
      const double without = meanErrorWithSlips(options, size, every);
      std::printf("slips up to %.2f every %d scans: mean error %.4f m, without the slip mixture %.4f m\n",
                  size, every, with_mixture, without);
      EXPECT_LT(with_mixture, 0.006);
      EXPECT_GT(without, 2.0 * with_mixture) << "the mechanism: without it the slips are carried on";
    }
  }
}

TEST(OdometryTracker, AConstantVelocitysGuessIsNotTakenForSlippingWheels) {
  // No wheels: each scan is predicted at the velocity of the last ones, which is wrong by a few of its
  // sigmas every time the robot starts or stops. The slip mixture weighs the wheels' faults; a velocity's
  // guess has its own noise model and no wheels to slip, so its prior is never softened. prior_weight is
  // the check that tells (0.11 at the stop and the start when the mixture weighed the guess); the poses
  // stay within 2 cm either way here.
  const Path stop_and_go = [](double t) {
    const double moving = std::min(t, 1.0) + std::clamp(t - 2.0, 0.0, 1.0);  // stands still from 1 s to 2 s
    return hglasm_test::rawPose(1.5 * moving, 0.0, 0.0);
  };
  Robot robot(withoutOdometry(), stop_and_go);
  int constant_velocity = 0;
  for (int i = 0; i <= 35; ++i) {
    const TrackerUpdate update = robot.step(0.1 * i);
    expectSane(update);
    if (update.diagnostics.prediction == PredictionSource::kConstantVelocity) ++constant_velocity;
    EXPECT_EQ(update.diagnostics.prior_weight, 1.0) << "scan " << i;
    hglasm_test::expectPoseNear(update.pose, robot.truth(0.1 * i), 0.02, hglasm_test::deg(0.5), "scan");
  }
  EXPECT_GT(constant_velocity, 30);
}

TEST(OdometryTracker, EmptyScansWithoutOdometryKeepTheConstantVelocity) {
  Robot robot(withoutOdometry(), straightPath(0.4));
  for (int i = 0; i <= 10; ++i) robot.step(0.1 * i);
  const TrackerUpdate before = robot.step(1.1);
  const hglasm::Scan empty;
  TrackerUpdate update;
  for (int i = 12; i <= 14; ++i) {
    update = robot.step(0.1 * i, &empty);
    expectSane(update);
    EXPECT_TRUE(update.fallback) << i;
    EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kConstantVelocity);
  }
  EXPECT_NEAR(update.pose.x, 0.4 * 1.4, 0.01);  // kept moving at 0.4 m/s
  EXPECT_NEAR(update.pose.y, 0.0, 0.01);
  EXPECT_GT(update.pose_covariance.trace(), before.pose_covariance.trace());
}

TEST(OdometryTracker, TooFewPointsAndNonFiniteScansAreFallbacks) {
  Robot robot(withoutOdometry(), straightPath(0.4));
  for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
  hglasm::Scan few = robot.scanAt(0.6);
  few.points.resize(5);
  few.beam_index.resize(5);
  TrackerUpdate update = robot.step(0.6, &few);
  expectSane(update);
  EXPECT_TRUE(update.fallback);
  hglasm::Scan garbage = robot.scanAt(0.7);
  for (auto& p : garbage.points) p = Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 1.0);
  update = robot.step(0.7, &garbage);
  expectSane(update);
  EXPECT_TRUE(update.fallback);
  update = robot.tracker().processScan(std::numeric_limits<double>::quiet_NaN(), robot.scanAt(0.8));
  expectSane(update);
  update = robot.step(0.8);
  expectSane(update);
  EXPECT_NEAR(update.pose.x, 0.32, 0.02);
}

TEST(OdometryTracker, ExplicitResetRestartsAtTheOrigin) {
  Robot robot(withoutOdometry(), straightPath(0.4));
  for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
  robot.tracker().reset();
  const TrackerUpdate update = robot.step(0.6);
  expectSane(update);
  EXPECT_TRUE(update.reset);
  EXPECT_FALSE(update.matched);
  EXPECT_EQ(update.pose.x, 0.0);
  EXPECT_EQ(robot.tracker().pose().x, 0.0);
}

Eigen::Matrix3d someCovariance() {
  Eigen::Matrix3d covariance;
  covariance << 0.04, 0.01, 0.0, 0.01, 0.09, 0.002, 0.0, 0.002, 0.01;
  return covariance;
}

TEST(OdometryTracker, SetPoseContinuesFromTheGivenPoseWithTheWheelMotionSince) {
  Robot robot(TrackerOptions(), straightPath(0.4));
  robot.enableOdometry(0.0, 0.0);
  for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
  const Pose2D set(2.0, -1.0, 0.5);
  ASSERT_TRUE(robot.tracker().setPose(0.5, set, someCovariance()));
  hglasm_test::expectPoseNear(robot.tracker().pose(), set, 1e-12, 1e-12, "robot.tracker().pose()");
  // The next scan, 0.1 s later: the set pose moved on by the wheels' 4 cm, its covariance grown by theirs.
  const TrackerUpdate first = robot.step(0.6);
  expectSane(first);
  EXPECT_TRUE(first.reset);
  EXPECT_FALSE(first.matched);
  EXPECT_TRUE(first.new_keyframe);
  hglasm_test::expectPoseNear(first.pose, set * Pose2D(0.04, 0.0, 0.0), 1e-9, 1e-9, "first after setPose");
  EXPECT_GT(first.pose_covariance(0, 0), someCovariance()(0, 0));
  EXPECT_NEAR(first.pose_covariance(0, 0), someCovariance()(0, 0), 0.01);
  // Later scans: the set pose composed with the motion since (the matches against the new keyframe).
  TrackerUpdate update;
  for (int i = 7; i <= 20; ++i) {
    update = robot.step(0.1 * i);
    expectSane(update);
    EXPECT_FALSE(update.reset);
  }
  EXPECT_TRUE(update.matched);
  hglasm_test::expectPoseNear(update.pose, set * Pose2D(0.4 * 1.5, 0.0, 0.0), 0.02, 0.01, "after 1.5 s");
}

TEST(OdometryTracker, SetPoseAtTheScanStampKeepsTheGivenCovariance) {
  Robot robot(withoutOdometry(), straightPath(0.4));
  for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
  const Pose2D set(-3.0, 4.0, -2.0);
  ASSERT_TRUE(robot.tracker().setPose(0.6, set, someCovariance()));
  const TrackerUpdate first = robot.step(0.6);
  EXPECT_TRUE(first.reset);
  hglasm_test::expectPoseNear(first.pose, set, 1e-12, 1e-12, "first.pose");
  EXPECT_TRUE(first.pose_covariance.isApprox(someCovariance(), 1e-12)) << first.pose_covariance;
  const TrackerUpdate second = robot.step(0.7);
  EXPECT_TRUE(second.matched);
  hglasm_test::expectPoseNear(second.pose, set * Pose2D(0.04, 0.0, 0.0), 0.01, 0.005, "second");
  EXPECT_GE(second.pose_covariance(0, 0), someCovariance()(0, 0));
}

TEST(OdometryTracker, ResetAndSetPoseInterleavedTheLastOneWins) {
  Robot robot(withoutOdometry(), straightPath(0.4));
  for (int i = 0; i <= 3; ++i) robot.step(0.1 * i);
  const Pose2D set(1.0, 2.0, 0.3);
  ASSERT_TRUE(robot.tracker().setPose(0.3, set, someCovariance()));
  robot.tracker().reset();
  TrackerUpdate update = robot.step(0.4);
  EXPECT_TRUE(update.reset);
  hglasm_test::expectPoseNear(update.pose, Pose2D(), 1e-12, 1e-12, "update.pose");
  EXPECT_EQ(update.pose_covariance, Eigen::Matrix3d::Zero());

  robot.tracker().reset();
  ASSERT_TRUE(robot.tracker().setPose(0.5, set, someCovariance()));
  update = robot.step(0.5);
  EXPECT_TRUE(update.reset);
  hglasm_test::expectPoseNear(update.pose, set, 1e-12, 1e-12, "update.pose");

  const Pose2D other(-1.0, 0.5, -0.1);
  ASSERT_TRUE(robot.tracker().setPose(0.6, set, someCovariance()));
  ASSERT_TRUE(robot.tracker().setPose(0.6, other, Eigen::Matrix3d::Zero()));
  update = robot.step(0.6);
  EXPECT_TRUE(update.reset);
  hglasm_test::expectPoseNear(update.pose, other, 1e-12, 1e-12, "update.pose");
  EXPECT_EQ(update.pose_covariance, Eigen::Matrix3d::Zero());
  update = robot.step(0.7);
  EXPECT_FALSE(update.reset);
  hglasm_test::expectPoseNear(update.pose, other * Pose2D(0.04, 0.0, 0.0), 0.01, 0.005, "after two");
}

TEST(OdometryTracker, SetPoseRejectsInvalidInputAndChangesNothing) {
  Robot robot(withoutOdometry(), straightPath(0.4));
  for (int i = 0; i <= 5; ++i) robot.step(0.1 * i);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d asymmetric = someCovariance();
  asymmetric(0, 1) += 0.01;
  Eigen::Matrix3d indefinite = someCovariance();
  indefinite(2, 2) = -0.01;
  Eigen::Matrix3d not_finite = someCovariance();
  not_finite(1, 1) = inf;
  OdometryTracker& tracker = robot.tracker();
  const Pose2D before = tracker.pose();
  EXPECT_FALSE(tracker.setPose(nan, Pose2D(1.0, 1.0, 0.0), someCovariance()));
  EXPECT_FALSE(tracker.setPose(0.5, hglasm_test::rawPose(nan, 1.0, 0.0), someCovariance()));
  EXPECT_FALSE(tracker.setPose(0.5, hglasm_test::rawPose(1.0, inf, 0.0), someCovariance()));
  EXPECT_FALSE(tracker.setPose(0.5, hglasm_test::rawPose(1.0, 1.0, nan), someCovariance()));
  EXPECT_FALSE(tracker.setPose(0.5, Pose2D(1.0, 1.0, 0.0), asymmetric));
  EXPECT_FALSE(tracker.setPose(0.5, Pose2D(1.0, 1.0, 0.0), indefinite));
  EXPECT_FALSE(tracker.setPose(0.5, Pose2D(1.0, 1.0, 0.0), not_finite));
  hglasm_test::expectPoseNear(tracker.pose(), before, 1e-12, 1e-12, "tracker.pose()");
  const TrackerUpdate update = robot.step(0.6);
  EXPECT_FALSE(update.reset);
  EXPECT_TRUE(update.matched);
  hglasm_test::expectPoseNear(update.pose, Pose2D(0.24, 0.0, 0.0), 0.01, 0.005, "tracking went on");
  EXPECT_TRUE(hglasm::isValidPoseCovariance(someCovariance()));
  EXPECT_TRUE(hglasm::isValidPoseCovariance(Eigen::Matrix3d::Zero()));
  EXPECT_FALSE(hglasm::isValidPoseCovariance(indefinite));
}

}  // namespace

namespace {

struct FastTurnRun {
  double translation_error = 0.0;  ///< of the final pose, m
  double rotation_error = 0.0;     ///< of the final pose, rad
  double worst_rotation_error = 0.0;
  int fallbacks = 0, leaps = 0, rotations_from_imu = 0, scans = 0;
  double learned_bias = 0.0;  ///< the tracker's gyro bias at the end, rad/s
};

/// Two laps of the square with spins at `turn_rate`, scans at `scan_rate` Hz, wheels that count
/// `turn_scale` of each turn; with a gyro of `bias` and `noise_density` if `use_imu`, under `gyro`'s model;
/// each scan's beams measured over `sweep_fraction` of the scan period (0: all at once).
FastTurnRun runFastTurns(bool use_imu, double turn_rate, double scan_rate, double turn_scale, double bias,
                         double noise_density, const hglasm::GyroOptions& gyro = {},
                         double sweep_fraction = 0.0, bool confirm_leaps = true) {
  TrackerOptions options;
  options.leap.confirm = confirm_leaps;
  options.prediction.use_imu = use_imu;
  options.prediction.imu = gyro;
  const Path path = hglasm_test::squareWithSpins(turn_rate);
  Robot robot(options, path);
  robot.enableOdometry(0.0, 0.0, turn_scale);
  robot.setSweepTime(sweep_fraction / scan_rate);
  if (use_imu) robot.enableGyro(bias, noise_density, 7);
  const double lap = 4.0 * (3.0 + (kPi / 2) / turn_rate);
  FastTurnRun run;
  TrackerUpdate update;
  for (int i = 0; i / scan_rate <= 2.0 * lap; ++i) {
    const double t = i / scan_rate;
    update = robot.step(t);
    expectSane(update);
    run.fallbacks += update.fallback;
    run.leaps += update.leap;
    run.rotations_from_imu += update.diagnostics.rotation_from_imu;
    run.scans += i > 0;
    run.worst_rotation_error =
        std::max(run.worst_rotation_error, hglasm_test::rotationError(update.pose, robot.truth(t)));
  }
  run.learned_bias = update.diagnostics.learned.imu_bias;
  run.translation_error = hglasm_test::translationError(update.pose, robot.truth(update.stamp));
  run.rotation_error = hglasm_test::rotationError(update.pose, robot.truth(update.stamp));
  return run;
}

// The gyro of these runs is a pessimistic one: an uncalibrated bias of 1.7 deg/s, six times the default
// prior's 0.005 rad/s (it is learned from the matches), and white noise of 0.005 rad/s per sqrt(Hz)
// (0.29 deg/s per sqrt(Hz): 2.5 times the default model's angle random walk, 20 to 50 times a consumer MEMS
// gyro's datasheet figure).
constexpr double kGyroBias = 0.03;
constexpr double kGyroNoiseDensity = 0.005;

/// The figures of a run, for the README and the closing notes (ctest's log keeps them).
void printRun(const char* what, const FastTurnRun& run) {
  std::printf(
      "%-28s final %.4f m %.3f deg, worst heading %.3f deg, leaps %d, fallbacks %d, IMU steps %d/%d, "
      "learned bias %.4f rad/s\n",
      what, run.translation_error, run.rotation_error * 180.0 / kPi, run.worst_rotation_error * 180.0 / kPi,
      run.leaps, run.fallbacks, run.rotations_from_imu, run.scans, run.learned_bias);
}

TEST(OdometryTracker, AGyroTracksFastTurnsThatTheWheelsGetWrong) {
  // A 5 Hz laser (a low-cost 360-degree scanner), spins at 180 deg/s: 36 degrees between scans, of which
  // the slipping wheels count 30 %. The wheels' 25-degree error per scan is far beyond their noise model,
  // and only at the spins: wheels right everywhere else earn the trust that makes a leap wait for the next
  // scan's confirmation, which a spin's growing error never gives, and the wheels alone are lost. Without
  // that (leap/confirm false) the leap test recovers every spin, leaping each time; with the gyro the
  // prediction holds.
  const FastTurnRun wheels = runFastTurns(false, kPi, 5.0, 0.3, 0.0, 0.0);
  const FastTurnRun unconfirmed = runFastTurns(false, kPi, 5.0, 0.3, 0.0, 0.0, {}, 0.0, false);
  const FastTurnRun gyro = runFastTurns(true, kPi, 5.0, 0.3, kGyroBias, kGyroNoiseDensity);
  printRun("5 Hz, wheels alone:", wheels);
  printRun("5 Hz, wheels, leaps at once:", unconfirmed);
  printRun("5 Hz, gyro:", gyro);
  EXPECT_GT(wheels.worst_rotation_error, hglasm_test::deg(20.0)) << "the scenario is not hard for the wheels";
  EXPECT_GE(unconfirmed.leaps, 20);
  EXPECT_LT(unconfirmed.worst_rotation_error, hglasm_test::deg(1.0));
  EXPECT_EQ(gyro.rotations_from_imu, gyro.scans) << "every step's rotation from the gyro";
  EXPECT_EQ(gyro.fallbacks, 0);
  EXPECT_EQ(gyro.leaps, 0);
  EXPECT_LT(gyro.translation_error, 0.01);
  EXPECT_LT(gyro.rotation_error, hglasm_test::deg(0.3));
  EXPECT_LT(gyro.worst_rotation_error, hglasm_test::deg(0.5));
  EXPECT_NEAR(gyro.learned_bias, kGyroBias, 0.005) << "the bias learned from the matches";
}

TEST(OdometryTracker, AGrosslyBiasedGyroIsLearnedInTheFirstSeconds) {
  // 0.5 rad/s (29 deg/s), a hundred times the prior: the first steps leap, then the bias is known.
  const FastTurnRun gyro = runFastTurns(true, kPi, 5.0, 0.3, 0.5, kGyroNoiseDensity);
  printRun("5 Hz, gyro biased 0.5 rad/s:", gyro);
  EXPECT_NEAR(gyro.learned_bias, 0.5, 0.005);
  EXPECT_LE(gyro.leaps, 5);
  EXPECT_EQ(gyro.fallbacks, 0);
  EXPECT_LT(gyro.worst_rotation_error, hglasm_test::deg(2.0));
  EXPECT_LT(gyro.rotation_error, hglasm_test::deg(0.3));
}

TEST(OdometryTracker, WithoutLearningTheGyroBiasTheSameRunNeedsLeaps) {
  // The learning matters: the same run with the bias left to the prior's 0.005 rad/s.
  hglasm::GyroOptions fixed;
  fixed.estimate_bias = false;
  const FastTurnRun learned = runFastTurns(true, kPi, 5.0, 0.3, kGyroBias, kGyroNoiseDensity);
  const FastTurnRun unlearned = runFastTurns(true, kPi, 5.0, 0.3, kGyroBias, kGyroNoiseDensity, fixed);
  printRun("5 Hz, gyro, bias not learned:", unlearned);
  EXPECT_EQ(unlearned.learned_bias, 0.0);
  EXPECT_GT(unlearned.leaps, learned.leaps);
  EXPECT_GT(unlearned.worst_rotation_error, learned.worst_rotation_error);
}

TEST(OdometryTracker, AGyroSparesTheLeapsThatFastTurnsOtherwiseNeed) {
  // 10 Hz, 180 deg/s, wheels counting half of each turn: 9 degrees off per scan. The leap test taking leaps
  // at once (leap/confirm false) recovers every one of them (flagged as leaps); with the gyro the prediction
  // holds and no leap is needed.
  const FastTurnRun wheels = runFastTurns(false, kPi, 10.0, 0.5, 0.0, 0.0, {}, 0.0, false);
  const FastTurnRun gyro = runFastTurns(true, kPi, 10.0, 0.5, kGyroBias, kGyroNoiseDensity);
  printRun("10 Hz, wheels, leaps at once:", wheels);
  printRun("10 Hz, gyro:", gyro);
  EXPECT_GE(wheels.leaps, 20);
  EXPECT_LE(gyro.leaps, 2);
  EXPECT_EQ(gyro.fallbacks, 0);
  EXPECT_LT(gyro.translation_error, 0.01);
  EXPECT_LT(gyro.worst_rotation_error, hglasm_test::deg(0.5));
}

TEST(OdometryTracker, WithASweepingLaserTheGyroDeskewsTheSpins) {
  // A laser whose sweep takes 90 % of its period: at 180 deg/s a 10 Hz sweep is sheared by 16 degrees, and
  // a spin starts and stops within a sweep, where the velocity of the last poses says nothing. The gyro
  // gives the turn at every beam.
  const FastTurnRun wheels = runFastTurns(false, kPi, 10.0, 0.5, 0.0, 0.0, {}, 0.9);
  const FastTurnRun gyro = runFastTurns(true, kPi, 10.0, 0.5, kGyroBias, kGyroNoiseDensity, {}, 0.9);
  const FastTurnRun slow = runFastTurns(true, kPi, 5.0, 0.3, kGyroBias, kGyroNoiseDensity, {}, 0.9);
  printRun("10 Hz sweeping, wheels alone:", wheels);
  printRun("10 Hz sweeping, gyro:", gyro);
  printRun("5 Hz sweeping, gyro:", slow);
  EXPECT_GT(wheels.worst_rotation_error, hglasm_test::deg(10.0)) << "the scenario is not hard for the wheels";
  // A handful of steps leave the gyro's tight prediction by more than 4 sigma (millimetres), against the
  // wheels' leap at nearly every spin.
  EXPECT_LT(5 * gyro.leaps, wheels.leaps);
  EXPECT_LT(gyro.translation_error, 0.02);
  EXPECT_LT(gyro.worst_rotation_error, hglasm_test::deg(1.0));
  // At 5 Hz a sheared sweep may fit better elsewhere (its de-skewed beams still graze the walls): a few
  // leaps (at most one step in twenty; the wheels alone leap at every spin) are allowed when the pose stays
  // within the bounds.
  EXPECT_LE(20 * slow.leaps, slow.scans);
  EXPECT_LT(slow.translation_error, 0.05);
  EXPECT_LT(slow.worst_rotation_error, hglasm_test::deg(3.0));
  EXPECT_NEAR(gyro.learned_bias, kGyroBias, 0.01);
}

TEST(OdometryTracker, WhenTheGyroStopsTheWheelsPredictTheRotation) {
  TrackerOptions options;
  options.prediction.use_imu = true;
  Robot robot(options, circlePath);
  robot.enableOdometry(0.0, 0.0);
  robot.enableGyro(kGyroBias, kGyroNoiseDensity, 3);
  TrackerUpdate update;
  for (int i = 0; i <= 20; ++i) update = robot.step(0.1 * i);
  EXPECT_TRUE(update.diagnostics.rotation_from_imu);
  robot.disableGyro();
  for (int i = 21; i <= 40; ++i) {
    update = robot.step(0.1 * i);
    expectSane(update);
    if (i >= 23) {
      EXPECT_FALSE(update.diagnostics.rotation_from_imu) << "scan " << i << ": the gyro stopped at 2.0 s";
    }
    EXPECT_EQ(update.diagnostics.prediction, PredictionSource::kOdometry);
  }
  hglasm_test::expectPoseNear(update.pose, robot.truth(4.0), 0.02, hglasm_test::deg(0.5), "final pose");
}

}  // namespace
