// De-skewing a sweep with the base's motion: the velocity alone, a measured rotation that covers the sweep
// (with the velocity's translation), a laser mounted off the base's centre, and nothing known.
#include "hglasm_odometry/core/deskew.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"

namespace {

using hglasm::Pose2D;
using hglasm::Scan;

/// Four beams 10 ms apart, straight ahead of the laser at 2 m (as seen while it moved).
Scan sweep() {
  Scan scan;
  for (int i = 0; i < 4; ++i) {
    scan.points.emplace_back(2.0, 0.0);
    scan.beam_index.push_back(i);
  }
  scan.beam_count = 4;
  scan.time_increment = 0.01;
  return scan;
}

TEST(Deskew, LaserVelocityAddsTheLeverArmAndTurnsIntoTheLaserFrame) {
  // Base turning at 1 rad/s, laser 0.5 m ahead: it moves sideways at 0.5 m/s; mounted turned by +90 deg
  // that sideways motion is along its own -x.
  const Eigen::Vector3d v = hglasm::laserVelocity(Pose2D(0.5, 0.0, M_PI / 2), Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_NEAR(v.x(), 0.5, 1e-12);
  EXPECT_NEAR(v.y(), 0.0, 1e-12);
  EXPECT_NEAR(v.z(), 1.0, 1e-12);
  const Eigen::Vector3d ahead = hglasm::laserVelocity(Pose2D(0.5, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_NEAR(ahead.x(), 1.0, 1e-12);
  EXPECT_NEAR(ahead.y(), 0.0, 1e-12);
}

TEST(Deskew, NothingKnownMeansNoCompensation) {
  Scan out;
  out.beam_count = -1;
  EXPECT_FALSE(hglasm::deskewSweep(sweep(), 0.0, Pose2D(), hglasm::SweepMotion(), &out));
  EXPECT_EQ(out.beam_count, -1) << "untouched";
  Scan no_times = sweep();
  no_times.time_increment = 0.0;
  hglasm::SweepMotion motion;
  motion.base_velocity = Eigen::Vector3d(1.0, 0.0, 0.0);
  EXPECT_FALSE(hglasm::deskewSweep(no_times, 0.0, Pose2D(), motion, &out));
}

TEST(Deskew, TheVelocityMovesEachBeamByItsTime) {
  hglasm::SweepMotion motion;
  motion.base_velocity = Eigen::Vector3d(1.0, 0.0, 0.0);
  Scan out;
  ASSERT_TRUE(hglasm::deskewSweep(sweep(), 5.0, Pose2D(), motion, &out));
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(out.points[i].x(), 2.0 + 0.01 * i, 1e-12) << i;
}

TEST(Deskew, AMeasuredRotationThatCoversTheSweepGivesTheTurn) {
  // The velocity says no turn; the IMU says 2 rad/s: the turn is the IMU's.
  hglasm::SweepMotion motion;
  motion.base_velocity = Eigen::Vector3d::Zero();
  double asked_from = -1.0;
  motion.base_rotation = [&](double from, double to, double* angle) {
    if (asked_from < 0.0) asked_from = from;
    *angle = 2.0 * (to - from);
    return true;
  };
  Scan out;
  ASSERT_TRUE(hglasm::deskewSweep(sweep(), 10.0, Pose2D(), motion, &out));
  EXPECT_EQ(asked_from, 10.0) << "rotations are read from the scan's stamp";
  for (int i = 0; i < 4; ++i) {
    const double angle = 2.0 * 0.01 * i;
    EXPECT_NEAR(out.points[i].x(), 2.0 * std::cos(angle), 1e-9) << i;
    EXPECT_NEAR(out.points[i].y(), 2.0 * std::sin(angle), 1e-9) << i;
  }
}

TEST(Deskew, ARotationThatDoesNotCoverTheSweepFallsBackToTheVelocity) {
  hglasm::SweepMotion motion;
  motion.base_velocity = Eigen::Vector3d(0.0, 0.0, -1.0);
  motion.base_rotation = [](double from, double to, double* angle) {
    *angle = 5.0 * (to - from);
    return to - from < 0.015;  // the samples stop half way through the sweep
  };
  Scan out;
  ASSERT_TRUE(hglasm::deskewSweep(sweep(), 0.0, Pose2D(), motion, &out));
  EXPECT_NEAR(out.points[3].y(), 2.0 * std::sin(-0.03), 1e-9) << "the velocity's turn, not the IMU's";
  motion.base_velocity.reset();
  EXPECT_FALSE(hglasm::deskewSweep(sweep(), 0.0, Pose2D(), motion, &out))
      << "and without it nothing is known";
}

TEST(Deskew, AMountedLaserTurnsAboutTheBase) {
  // Base turning at 1 rad/s with the laser 1 m ahead of it: the laser moves sideways as well as turning.
  hglasm::SweepMotion motion;
  motion.base_velocity = Eigen::Vector3d(0.0, 0.0, 1.0);
  motion.base_rotation = [](double from, double to, double* angle) {
    *angle = to - from;
    return true;
  };
  const Pose2D mount(1.0, 0.0, 0.0);
  Scan by_rotation, by_velocity;
  ASSERT_TRUE(hglasm::deskewSweep(sweep(), 0.0, mount, motion, &by_rotation));
  motion.base_rotation = nullptr;
  ASSERT_TRUE(hglasm::deskewSweep(sweep(), 0.0, mount, motion, &by_velocity));
  for (int i = 0; i < 4; ++i) {
    const double t = 0.01 * i;
    // The laser's pose at t in its frame at 0: mount^-1 * turn(t) * mount.
    const Pose2D laser = mount.inverse() * Pose2D(0.0, 0.0, t) * mount;
    const Eigen::Vector2d expected = laser * Eigen::Vector2d(2.0, 0.0);
    EXPECT_NEAR(by_rotation.points[i].x(), expected.x(), 1e-9) << i;
    EXPECT_NEAR(by_rotation.points[i].y(), expected.y(), 1e-9) << i;
    EXPECT_NEAR(by_velocity.points[i].y(), expected.y(), 1e-4) << i << ": first order";
  }
}

}  // namespace
