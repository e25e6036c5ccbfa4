// Wheel-odometry history: interpolation, the limits outside the buffered span, out-of-order and duplicate
// samples, rejection of non-finite input, and ageing.
#include "hglasm_odometry/core/odometry_buffer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test_util.h"

namespace {

using hglasm::OdometryBuffer;
using hglasm::Pose2D;

void expectPose(const Pose2D& actual, double x, double y, double theta, double tolerance = 1e-12) {
  EXPECT_NEAR(actual.x, x, tolerance);
  EXPECT_NEAR(actual.y, y, tolerance);
  EXPECT_NEAR(hglasm_test::angleDiff(actual.theta, theta), 0.0, tolerance);
}

TEST(OdometryBuffer, EmptyBufferHasNoPose) {
  OdometryBuffer buffer;
  Pose2D pose;
  EXPECT_TRUE(buffer.empty());
  EXPECT_EQ(buffer.size(), 0u);
  EXPECT_FALSE(buffer.poseAt(0.0, 1.0, &pose));
}

TEST(OdometryBuffer, InterpolatesBetweenSamples) {
  OdometryBuffer buffer;
  ASSERT_TRUE(buffer.add(10.0, Pose2D(0.0, 0.0, 0.0)));
  ASSERT_TRUE(buffer.add(11.0, Pose2D(1.0, -2.0, 0.2)));
  ASSERT_TRUE(buffer.add(12.0, Pose2D(1.0, -1.0, 0.4)));
  EXPECT_EQ(buffer.size(), 3u);
  EXPECT_DOUBLE_EQ(buffer.newestStamp(), 12.0);
  Pose2D pose;
  ASSERT_TRUE(buffer.poseAt(10.5, 0.0, &pose));
  expectPose(pose, 0.5, -1.0, 0.1);
  ASSERT_TRUE(buffer.poseAt(11.75, 0.0, &pose));
  expectPose(pose, 1.0, -1.25, 0.35);
  // Exactly at the samples.
  for (double stamp : {10.0, 11.0, 12.0}) {
    ASSERT_TRUE(buffer.poseAt(stamp, 0.0, &pose)) << stamp;
  }
  ASSERT_TRUE(buffer.poseAt(11.0, 0.0, &pose));
  expectPose(pose, 1.0, -2.0, 0.2);
  ASSERT_TRUE(buffer.poseAt(12.0, 0.0, &pose));
  expectPose(pose, 1.0, -1.0, 0.4);
}

TEST(OdometryBuffer, InterpolatesHeadingTheShortWayAcrossTheSeam) {
  OdometryBuffer buffer;
  buffer.add(0.0, Pose2D(0.0, 0.0, 3.0));
  buffer.add(1.0, Pose2D(0.0, 0.0, -3.0));
  Pose2D pose;
  ASSERT_TRUE(buffer.poseAt(0.5, 0.0, &pose));
  EXPECT_NEAR(hglasm_test::angleDiff(pose.theta, hglasm_test::kPi), 0.0, 1e-12);
  EXPECT_GT(pose.theta, -hglasm_test::kPi);
  EXPECT_LE(pose.theta, hglasm_test::kPi);
}

TEST(OdometryBuffer, ExtrapolatesAfterTheNewestAndHoldsBeforeTheOldestForMaxExtrapolation) {
  // Header: after the newest sample, extrapolate with the velocity over the last 0.05-1 s of samples;
  // before the oldest, hold it; at most max_extrapolation seconds either way.
  OdometryBuffer buffer;
  buffer.add(1.0, Pose2D(0.0, 0.0, 0.0));
  buffer.add(2.0, Pose2D(1.0, 0.0, 0.1));
  Pose2D pose;
  ASSERT_TRUE(buffer.poseAt(2.2, 0.25, &pose));
  expectPose(pose, 1.2, 0.0, 0.12, 1e-9);
  ASSERT_TRUE(buffer.poseAt(0.8, 0.25, &pose));
  expectPose(pose, 0.0, 0.0, 0.0);
  EXPECT_FALSE(buffer.poseAt(2.3, 0.25, &pose));
  EXPECT_FALSE(buffer.poseAt(0.7, 0.25, &pose));
  EXPECT_FALSE(buffer.poseAt(2.001, 0.0, &pose));
  EXPECT_FALSE(buffer.poseAt(100.0, 0.25, &pose));
  // A single sample has no velocity: it is held around its own stamp only.
  OdometryBuffer single;
  single.add(5.0, Pose2D(1.0, 2.0, 3.0));
  ASSERT_TRUE(single.poseAt(5.0, 0.0, &pose));
  expectPose(pose, 1.0, 2.0, 3.0);
  ASSERT_TRUE(single.poseAt(5.1, 0.25, &pose));
  expectPose(pose, 1.0, 2.0, 3.0);
  EXPECT_FALSE(single.poseAt(5.5, 0.25, &pose));
}

TEST(OdometryBuffer, ExtrapolationIgnoresNearSimultaneousPairs) {
  // intel logs odometry in pairs < 1 ms apart: their difference is noise, not velocity. 1 m/s forward,
  // with 1 cm of noise on the last sample 0.5 ms after its twin.
  OdometryBuffer buffer;
  buffer.add(0.5, Pose2D(0.5, 0.0, 0.0));
  buffer.add(1.0, Pose2D(1.0, 0.0, 0.0));
  buffer.add(1.0005, Pose2D(1.0105, 0.0, 0.0));
  Pose2D pose;
  ASSERT_TRUE(buffer.poseAt(1.2, 0.25, &pose));
  EXPECT_NEAR(pose.x, 1.21, 0.03);  // not 1.0105 + 0.2 * 21 m/s
  EXPECT_NEAR(pose.y, 0.0, 1e-12);
}

TEST(OdometryBuffer, OutOfOrderSamplesAreInsertedInPlace) {
  OdometryBuffer buffer;
  buffer.add(0.0, Pose2D(0.0, 0.0, 0.0));
  buffer.add(2.0, Pose2D(2.0, 0.0, 0.0));
  buffer.add(1.0, Pose2D(1.0, 5.0, 0.0));    // late
  buffer.add(-1.0, Pose2D(-1.0, 0.0, 0.0));  // even later, older than all
  EXPECT_EQ(buffer.size(), 4u);
  EXPECT_DOUBLE_EQ(buffer.newestStamp(), 2.0);
  Pose2D pose;
  ASSERT_TRUE(buffer.poseAt(1.0, 0.0, &pose));
  expectPose(pose, 1.0, 5.0, 0.0);
  ASSERT_TRUE(buffer.poseAt(1.5, 0.0, &pose));
  expectPose(pose, 1.5, 2.5, 0.0);
  ASSERT_TRUE(buffer.poseAt(0.5, 0.0, &pose));
  expectPose(pose, 0.5, 2.5, 0.0);
  ASSERT_TRUE(buffer.poseAt(-0.5, 0.0, &pose));
  expectPose(pose, -0.5, 0.0, 0.0);
}

TEST(OdometryBuffer, NonFiniteSamplesAreRejected) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  OdometryBuffer buffer;
  ASSERT_TRUE(buffer.add(1.0, Pose2D(0.0, 0.0, 0.0)));
  EXPECT_FALSE(buffer.add(nan, Pose2D(1.0, 0.0, 0.0)));
  EXPECT_FALSE(buffer.add(inf, Pose2D(1.0, 0.0, 0.0)));
  EXPECT_FALSE(buffer.add(-inf, Pose2D(1.0, 0.0, 0.0)));
  EXPECT_FALSE(buffer.add(2.0, hglasm_test::rawPose(nan, 0.0, 0.0)));
  EXPECT_FALSE(buffer.add(2.0, hglasm_test::rawPose(0.0, inf, 0.0)));
  EXPECT_FALSE(buffer.add(2.0, hglasm_test::rawPose(0.0, 0.0, nan)));
  EXPECT_EQ(buffer.size(), 1u);
  EXPECT_DOUBLE_EQ(buffer.newestStamp(), 1.0);
  Pose2D pose;
  EXPECT_FALSE(buffer.poseAt(nan, 1.0, &pose));
  ASSERT_TRUE(buffer.poseAt(1.0, 0.0, &pose));
  EXPECT_TRUE(pose.isFinite());
}

TEST(OdometryBuffer, DuplicateStampsNeverGiveNaN) {
  // intel samples odometry in pairs < 1 ms apart; exact duplicates must not divide by zero.
  OdometryBuffer buffer;
  buffer.add(0.0, Pose2D(0.0, 0.0, 0.0));
  buffer.add(1.0, Pose2D(1.0, 0.0, 0.0));
  buffer.add(1.0, Pose2D(1.1, 0.0, 0.0));
  buffer.add(1.0 + 1e-9, Pose2D(1.2, 0.0, 0.0));
  buffer.add(2.0, Pose2D(2.0, 0.0, 0.0));
  for (double stamp : {0.5, 1.0 - 1e-12, 1.0, 1.0 + 5e-10, 1.0 + 1e-9, 1.5, 2.0, 2.1}) {
    Pose2D pose;
    ASSERT_TRUE(buffer.poseAt(stamp, 0.25, &pose)) << stamp;
    EXPECT_TRUE(pose.isFinite()) << stamp;
    EXPECT_GE(pose.x, 0.0) << stamp;
    EXPECT_LE(pose.x, 2.2) << stamp;  // 2.1 is extrapolated at about 1 m/s
  }
}

TEST(OdometryBuffer, OldSamplesAgeOut) {
  OdometryBuffer buffer(5.0);
  for (int i = 0; i <= 100; ++i) buffer.add(0.1 * i, Pose2D(0.1 * i, 0.0, 0.0));
  EXPECT_LE(buffer.size(), 52u);  // about 5 s of 10 Hz samples
  EXPECT_GE(buffer.size(), 2u);
  Pose2D pose;
  EXPECT_FALSE(buffer.poseAt(1.0, 0.25, &pose));  // 9 s old: forgotten
  ASSERT_TRUE(buffer.poseAt(8.05, 0.0, &pose));
  EXPECT_NEAR(pose.x, 8.05, 1e-9);
  // A very long run stays bounded.
  OdometryBuffer long_run(1.0);
  for (int i = 0; i < 100000; ++i) long_run.add(0.001 * i, Pose2D());
  EXPECT_LE(long_run.size(), 1002u);
  buffer.clear();
  EXPECT_TRUE(buffer.empty());
  EXPECT_FALSE(buffer.poseAt(8.05, 1.0, &pose));
}

}  // namespace
