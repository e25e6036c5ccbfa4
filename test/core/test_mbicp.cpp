// MbICP: exact recovery of small motions on noise-free room scans (180 and 360 degrees, across the +-pi
// seam, any beam count, descending scans), statuses on bad input, and the featureless corridor.
#include "hglasm_odometry/core/mbicp.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>

#include "test_util.h"

namespace {

using hglasm::Mbicp;
using hglasm::MbicpResult;
using hglasm::MbicpStatus;
using hglasm::Pose2D;
using hglasm::Scan;
using hglasm_test::deg;
using hglasm_test::LaserSpec;

constexpr double kExactXy = 1e-3;                  // 1 mm
constexpr double kExactTheta = 0.01 * M_PI / 180;  // 0.01 degree

std::string describe(const MbicpResult& result) {
  std::ostringstream text;
  text << "pose " << result.pose.x << " " << result.pose.y << " " << result.pose.theta << ", status "
       << hglasm::toString(result.status) << ", iterations " << result.iterations << ", associations "
       << result.associations << ", rms " << result.rms_error;
  return text.str();
}

void expectSane(const MbicpResult& result) {
  EXPECT_TRUE(result.pose.isFinite()) << describe(result);
  EXPECT_TRUE(std::isfinite(result.rms_error)) << describe(result);
  EXPECT_GE(result.rms_error, 0.0);
  EXPECT_TRUE(hglasm_test::isValidCovariance(result.covariance)) << result.covariance;
  EXPECT_GE(result.associations, 0);
  EXPECT_GE(result.iterations, 0);
}

/// Reference scan at `reference_pose`, new scan at `new_pose` (world); MbICP from `initial` must find the
/// new pose in the reference frame.
MbicpResult matchInRoom(const hglasm_test::World& world, const LaserSpec& laser, const Pose2D& reference_pose,
                        const Pose2D& new_pose, const Pose2D& initial,
                        const hglasm::MbicpOptions& options = {}) {
  Mbicp mbicp(options);
  mbicp.setReference(hglasm_test::simulateScan(world, reference_pose, laser));
  return mbicp.match(hglasm_test::simulateScan(world, new_pose, laser), initial);
}

void expectExact(const MbicpResult& result, const Pose2D& truth) {
  expectSane(result);
  EXPECT_EQ(result.status, MbicpStatus::kConverged) << describe(result);
  EXPECT_LT(hglasm_test::translationError(result.pose, truth), kExactXy) << describe(result);
  EXPECT_LT(hglasm_test::rotationError(result.pose, truth), kExactTheta) << describe(result);
}

const std::vector<Pose2D> kSmallMotions = {
    Pose2D(0.05, -0.03, 0.02), Pose2D(0.10, 0.05, -0.05), Pose2D(-0.08, 0.10, 0.08),
    Pose2D(0.0, 0.0, 0.0),     Pose2D(0.15, 0.0, 0.0),    Pose2D(0.0, 0.0, deg(6.0)),
};

TEST(Mbicp, RecoversSmallMotionsExactlyOn180DegreeScans) {
  const auto world = hglasm_test::room();
  for (const Pose2D& motion : kSmallMotions) {
    SCOPED_TRACE(testing::Message() << "motion " << motion.x << " " << motion.y << " " << motion.theta);
    expectExact(matchInRoom(world, hglasm_test::halfCircleLaser(), Pose2D(), motion, Pose2D()), motion);
  }
}

TEST(Mbicp, RecoversSmallMotionsFromAnywhereInTheRoom) {
  // The reference is not at the origin: the answer is the motion in the reference's frame.
  const auto world = hglasm_test::room();
  const Pose2D reference(1.0, 0.5, 2.5);
  for (const Pose2D& motion : kSmallMotions) {
    SCOPED_TRACE(testing::Message() << "motion " << motion.x << " " << motion.y << " " << motion.theta);
    const Pose2D new_pose = hglasm_test::composeByHand(reference, motion);
    expectExact(matchInRoom(world, hglasm_test::halfCircleLaser(), reference, new_pose, Pose2D()), motion);
  }
}

TEST(Mbicp, RecoversSmallMotionsExactlyOn360DegreeScans) {
  const auto world = hglasm_test::room();
  for (const Pose2D& motion : kSmallMotions) {
    SCOPED_TRACE(testing::Message() << "motion " << motion.x << " " << motion.y << " " << motion.theta);
    expectExact(matchInRoom(world, hglasm_test::fullCircleLaser(), Pose2D(), motion, Pose2D()), motion);
  }
}

TEST(Mbicp, BearingWindowWrapsAtTheSeamOf360DegreeScans) {
  // With a one-degree window a new point near bearing +pi only finds its partner on the other side of the
  // seam (near -pi). Points behind the robot must still associate.
  hglasm::MbicpOptions narrow;
  narrow.bearing_window = deg(1.0);
  const auto world = hglasm_test::room();
  const Pose2D motion(0.02, 0.01, deg(0.6));
  const auto laser = hglasm_test::fullCircleLaser();
  Mbicp mbicp(narrow);
  mbicp.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  const Scan scan = hglasm_test::simulateScan(world, motion, laser);
  const MbicpResult result = mbicp.match(scan, Pose2D());
  expectExact(result, motion);
  // Nearly all points associate, including the ones around the seam (only trimming removes some).
  EXPECT_GE(result.associations, static_cast<int>(0.9 * scan.size())) << describe(result);
}

TEST(Mbicp, RecoversAMotionAcrossThePlusMinusPiSeam) {
  // The new scan is turned by about half a turn; the initial guess lies on the other side of +-pi.
  const auto world = hglasm_test::room();
  const Pose2D truth(0.05, 0.02, 3.12);
  for (const Pose2D& initial : {Pose2D(0.0, 0.0, -3.10), Pose2D(0.08, 0.0, 3.05), Pose2D(0.0, 0.05, -3.12)}) {
    SCOPED_TRACE(testing::Message() << "initial theta " << initial.theta);
    expectExact(matchInRoom(world, hglasm_test::fullCircleLaser(), Pose2D(), truth, initial), truth);
  }
  // The reference itself looks across the seam (heading pi in the world) and the robot turns past it.
  const Pose2D reference(0.3, -0.2, hglasm_test::kPi - 0.02);
  const Pose2D motion(0.06, -0.04, 0.05);
  const Pose2D new_pose = hglasm_test::composeByHand(reference, motion);
  ASSERT_LT(new_pose.theta, 0.0);  // wrapped to about -pi
  expectExact(matchInRoom(world, hglasm_test::fullCircleLaser(), reference, new_pose, Pose2D()), motion);
  expectExact(matchInRoom(world, hglasm_test::halfCircleLaser(), reference, new_pose, Pose2D()), motion);
}

TEST(Mbicp, AnyBeamCountAndDescendingScans) {
  const auto world = hglasm_test::room();
  const Pose2D motion(0.07, -0.05, 0.04);
  for (const LaserSpec& laser :
       {hglasm_test::laserSpec(hglasm_test::kPi, 180), hglasm_test::laserSpec(deg(270.0), 1081),
        hglasm_test::laserSpec(deg(239.0), 681, true), hglasm_test::laserSpec(deg(240.0), 2161),
        hglasm_test::fullCircleLaser(720), hglasm_test::laserSpec(hglasm_test::kPi, 361, true)}) {
    SCOPED_TRACE(testing::Message() << laser.beams << " beams, increment " << laser.angle_increment);
    expectExact(matchInRoom(world, laser, Pose2D(), motion, Pose2D()), motion);
  }
}

TEST(Mbicp, DifferentBeamCountsInReferenceAndNewScan) {
  const auto world = hglasm_test::room();
  const Pose2D motion(-0.05, 0.04, -0.03);
  Mbicp mbicp;
  mbicp.setReference(
      hglasm_test::simulateScan(world, Pose2D(), hglasm_test::laserSpec(hglasm_test::kPi, 361)));
  expectExact(
      mbicp.match(hglasm_test::simulateScan(world, motion, hglasm_test::laserSpec(hglasm_test::kPi, 181)),
                  Pose2D()),
      motion);
}

TEST(Mbicp, RepeatedMatchesAndInstancesAreIndependent) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const Scan reference = hglasm_test::simulateScan(world, Pose2D(), laser);
  const Scan scan_a = hglasm_test::simulateScan(world, Pose2D(0.05, 0.02, 0.03), laser);
  const Scan scan_b = hglasm_test::simulateScan(world, Pose2D(-0.04, 0.08, -0.02), laser);
  Mbicp first, second;
  first.setReference(reference);
  second.setReference(reference);
  const MbicpResult a1 = first.match(scan_a, Pose2D());
  const MbicpResult b = first.match(scan_b, Pose2D());
  const MbicpResult a2 = first.match(scan_a, Pose2D());
  const MbicpResult a3 = second.match(scan_a, Pose2D());
  EXPECT_EQ(a1.pose.x, a2.pose.x);
  EXPECT_EQ(a1.pose.theta, a2.pose.theta);
  EXPECT_EQ(a1.iterations, a2.iterations);
  EXPECT_EQ(a1.pose.x, a3.pose.x);
  EXPECT_EQ(a1.pose.y, a3.pose.y);
  EXPECT_NE(a1.pose.x, b.pose.x);
  EXPECT_TRUE(first.hasReference());
}

TEST(Mbicp, NoReferenceOrEmptyScansAreTooFewAssociations) {
  const auto world = hglasm_test::room();
  const Scan room_scan = hglasm_test::simulateScan(world, Pose2D(), hglasm_test::halfCircleLaser());
  const Pose2D initial(0.1, 0.2, 0.3);

  Mbicp no_reference;
  EXPECT_FALSE(no_reference.hasReference());
  MbicpResult result = no_reference.match(room_scan, initial);
  EXPECT_EQ(result.status, MbicpStatus::kTooFewAssociations);
  expectSane(result);

  Mbicp empty_reference;
  empty_reference.setReference(Scan());
  EXPECT_FALSE(empty_reference.hasReference());
  result = empty_reference.match(room_scan, initial);
  EXPECT_EQ(result.status, MbicpStatus::kTooFewAssociations);
  expectSane(result);

  Mbicp mbicp;
  mbicp.setReference(room_scan);
  result = mbicp.match(Scan(), initial);
  EXPECT_EQ(result.status, MbicpStatus::kTooFewAssociations);
  expectSane(result);

  Scan one_point;
  one_point.points = {room_scan.points[100]};
  one_point.beam_index = {100};
  one_point.beam_count = 361;
  result = mbicp.match(one_point, Pose2D());
  EXPECT_EQ(result.status, MbicpStatus::kTooFewAssociations) << describe(result);
  expectSane(result);

  Mbicp one_point_reference;
  one_point_reference.setReference(one_point);
  result = one_point_reference.match(room_scan, Pose2D());
  EXPECT_EQ(result.status, MbicpStatus::kTooFewAssociations) << describe(result);
  expectSane(result);
}

TEST(Mbicp, NothingWithinTheGateIsTooFewAssociations) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  Mbicp mbicp;
  mbicp.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  // The same scene moved 50 m away: nothing lies within 0.3 m.
  const MbicpResult result =
      mbicp.match(hglasm_test::simulateScan(world, Pose2D(), laser), Pose2D(50.0, 0.0, 0.0));
  EXPECT_EQ(result.status, MbicpStatus::kTooFewAssociations) << describe(result);
  expectSane(result);
}

TEST(Mbicp, NonFinitePointsAndInitialGuessesGiveFiniteNumbers) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Scan reference = hglasm_test::simulateScan(world, Pose2D(), laser);
  Scan scan = hglasm_test::simulateScan(world, Pose2D(0.05, 0.0, 0.02), laser);
  // A caller that forgot to filter: a few non-finite points in both scans.
  for (int i : {3, 50, 200}) {
    reference.points[i] = Eigen::Vector2d(nan, 1.0);
    scan.points[i + 1] = Eigen::Vector2d(inf, -inf);
  }
  Mbicp mbicp;
  mbicp.setReference(reference);
  const MbicpResult result = mbicp.match(scan, Pose2D());
  expectSane(result);
  EXPECT_LT(hglasm_test::translationError(result.pose, Pose2D(0.05, 0.0, 0.02)), 0.01) << describe(result);
  const MbicpResult bad_guess = mbicp.match(scan, hglasm_test::rawPose(nan, 0.0, inf));
  expectSane(bad_guess);
}

TEST(Mbicp, FeaturelessCorridorIsDegenerateOrUncertainAlongTheCorridor) {
  // Two parallel walls 2 m apart, far longer than the laser's range: nothing fixes x.
  const auto world = hglasm_test::corridor(1.0, 200.0);
  const auto laser = hglasm_test::laserSpec(deg(270.0), 541, false, 8.0);
  const Pose2D truth(0.20, 0.03, 0.02);
  const MbicpResult result = matchInRoom(world, laser, Pose2D(), truth, Pose2D());
  expectSane(result);
  const double along = result.covariance(0, 0);
  const double across = result.covariance(1, 1);
  EXPECT_TRUE(result.status == MbicpStatus::kDegenerate || along > 100.0 * across)
      << describe(result) << "\ncovariance\n"
      << result.covariance;
  EXPECT_GT(along, 100.0 * across) << result.covariance;  // the covariance says which axis is unknown
  // The constrained axes are still right (no jump sideways or in heading).
  EXPECT_NEAR(result.pose.y, truth.y, 0.01) << describe(result);
  EXPECT_NEAR(hglasm_test::angleDiff(result.pose.theta, truth.theta), 0.0, deg(0.5)) << describe(result);
  // No jump along the corridor either: it stays near the guess or the truth.
  EXPECT_LT(std::abs(result.pose.x), 0.5) << describe(result);
}

TEST(Mbicp, CovarianceOfAWellConstrainedRoomIsSmall) {
  const auto world = hglasm_test::room();
  const MbicpResult result =
      matchInRoom(world, hglasm_test::halfCircleLaser(), Pose2D(), Pose2D(0.05, 0.05, 0.05), Pose2D());
  expectSane(result);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(result.covariance);
  EXPECT_GT(solver.eigenvalues().minCoeff(), 0.0);
  EXPECT_LT(result.covariance(0, 0), 1e-3);  // below (3 cm)^2
  EXPECT_LT(result.covariance(1, 1), 1e-3);
  EXPECT_LT(result.covariance(2, 2), 1e-3);
}

TEST(Mbicp, StatusStringsAreDistinct) {
  std::set<std::string> names;
  for (MbicpStatus status : {MbicpStatus::kConverged, MbicpStatus::kMaxIterations,
                             MbicpStatus::kTooFewAssociations, MbicpStatus::kDegenerate}) {
    ASSERT_NE(hglasm::toString(status), nullptr);
    names.insert(hglasm::toString(status));
  }
  EXPECT_EQ(names.size(), 4u);
}

TEST(Mbicp, IterationLimitIsReported) {
  hglasm::MbicpOptions options;
  options.max_iterations = 1;
  const auto world = hglasm_test::room();
  const MbicpResult result = matchInRoom(world, hglasm_test::halfCircleLaser(), Pose2D(),
                                         Pose2D(0.1, 0.05, 0.05), Pose2D(), options);
  expectSane(result);
  EXPECT_EQ(result.iterations, 1);
  EXPECT_EQ(result.status, MbicpStatus::kMaxIterations) << describe(result);
}

// ------------------------------------------------------------------ with a prior on the pose

hglasm::PosePrior priorAt(const Pose2D& mean, double sigma_xy, double sigma_theta) {
  hglasm::PosePrior prior;
  prior.mean = mean;
  prior.information = Eigen::Vector3d(1.0 / (sigma_xy * sigma_xy), 1.0 / (sigma_xy * sigma_xy),
                                      1.0 / (sigma_theta * sigma_theta))
                          .asDiagonal();
  return prior;
}

TEST(MbicpWithPrior, InAFeaturelessCorridorThePriorDecidesTheAxisTheScanCannotSee) {
  const auto world = hglasm_test::corridor(1.0, 200.0);
  const auto laser = hglasm_test::laserSpec(deg(270.0), 541, false, 8.0);
  const Pose2D truth(0.40, 0.02, 0.01);
  Mbicp mbicp;
  mbicp.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  const Scan scan = hglasm_test::simulateScan(world, truth, laser);
  const hglasm::PosePrior prior = priorAt(Pose2D(0.25, 0.0, 0.0), 0.05, 0.05);
  const MbicpResult result = mbicp.match(scan, prior.mean, &prior);
  expectSane(result);
  EXPECT_EQ(result.status, MbicpStatus::kConverged)
      << describe(result) << ": with a prior, degeneracy is no failure";
  EXPECT_TRUE(result.degenerate);
  EXPECT_NEAR(result.pose.x, 0.25, 2e-3) << "along the corridor: the prior's mean";
  EXPECT_NEAR(result.pose.y, truth.y, 2e-3) << "across: the scan";
  EXPECT_NEAR(hglasm_test::angleDiff(result.pose.theta, truth.theta), 0.0, deg(0.05)) << "heading: the scan";
  // The posterior: the prior's spread along the corridor, the scan's (far smaller) across it.
  EXPECT_NEAR(std::sqrt(result.covariance(0, 0)), 0.05, 0.005) << result.covariance;
  EXPECT_LT(result.covariance(1, 1), 0.01 * result.covariance(0, 0)) << result.covariance;
}

TEST(MbicpWithPrior, AWellConstrainedScanOutweighsAWeakPrior) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const Pose2D truth(0.10, -0.05, 0.03);
  Mbicp mbicp;
  mbicp.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  const hglasm::PosePrior prior = priorAt(Pose2D(0.15, 0.0, 0.05), 0.1, 0.1);
  const MbicpResult result = mbicp.match(hglasm_test::simulateScan(world, truth, laser), prior.mean, &prior);
  expectExact(result, truth);
  EXPECT_FALSE(result.degenerate);
  EXPECT_LT(hglasm_test::translationError(result.scan_only_pose, truth), kExactXy);
}

TEST(MbicpWithPrior, APosteriorIsTheInformationWeightedMeanOfScanAndPrior) {
  // A strong prior 3 cm off: the result is where the two informations balance (to first order).
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const Pose2D truth(0.10, -0.05, 0.03);
  hglasm::MbicpOptions options;
  options.independent_points = 5.0;  // a weak scan, so that the prior visibly pulls
  Mbicp mbicp(options);
  mbicp.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  const Scan scan = hglasm_test::simulateScan(world, truth, laser);
  const hglasm::PosePrior prior = priorAt(Pose2D(0.13, -0.05, 0.03), 0.01, 0.01);
  const MbicpResult result = mbicp.match(scan, truth, &prior);
  expectSane(result);
  const Eigen::Matrix3d& scan_information = result.scan_information;
  const Eigen::Vector3d scan_only(truth.x, truth.y, truth.theta);
  const Eigen::Vector3d mean(prior.mean.x, prior.mean.y, prior.mean.theta);
  const Eigen::Vector3d expected = (scan_information + prior.information)
                                       .ldlt()
                                       .solve(scan_information * scan_only + prior.information * mean);
  EXPECT_GT(result.pose.x - truth.x, 0.002) << "the prior pulls";
  EXPECT_LT(result.pose.x - truth.x, 0.028) << "the scan pulls back";
  EXPECT_NEAR(result.pose.x, expected.x(), 1e-3) << describe(result);
  EXPECT_NEAR(result.pose.y, expected.y(), 1e-3) << describe(result);
  EXPECT_NEAR(result.pose.theta, expected.z(), 1e-4) << describe(result);
  // Where the scan alone would be: the truth.
  EXPECT_LT(hglasm_test::translationError(result.scan_only_pose, truth), 2e-3);
  // And the posterior covariance is the inverse of the summed information.
  const Eigen::Matrix3d posterior = (scan_information + prior.information).inverse();
  EXPECT_LT((result.covariance - posterior).cwiseAbs().maxCoeff(), 1e-3 * posterior.cwiseAbs().maxCoeff());
}

TEST(MbicpWithPrior, IndependentPointsDivideTheInformation) {
  // n associations count as at most independent_points: the covariance grows by n / independent_points.
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const Pose2D truth(0.05, 0.02, 0.01);
  const MbicpResult all = matchInRoom(world, laser, Pose2D(), truth, Pose2D());
  hglasm::MbicpOptions options;
  options.independent_points = 20.0;
  const MbicpResult twenty = matchInRoom(world, laser, Pose2D(), truth, Pose2D(), options);
  ASSERT_GT(all.associations, 200);
  EXPECT_LT(hglasm_test::translationError(all.pose, twenty.pose), 1e-9) << "the estimate does not change";
  const double ratio = twenty.covariance(0, 0) / all.covariance(0, 0);
  EXPECT_GT(ratio, 0.9 * all.associations / 20.0);
  EXPECT_LT(ratio, 1.1 * all.associations / 20.0);
  options.independent_points = 1e6;  // more than there are points: every point counts once
  const MbicpResult capped = matchInRoom(world, laser, Pose2D(), truth, Pose2D(), options);
  EXPECT_NEAR(capped.covariance(0, 0), all.covariance(0, 0), 1e-12);
}

TEST(MbicpWithPrior, ANonFinitePriorIsIgnored) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const Pose2D truth(0.05, 0.02, 0.01);
  Mbicp mbicp;
  mbicp.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  hglasm::PosePrior prior = priorAt(Pose2D(std::nan(""), 0.0, 0.0), 0.01, 0.01);
  expectExact(mbicp.match(hglasm_test::simulateScan(world, truth, laser), Pose2D(), &prior), truth);
}

TEST(Mbicp, SeveralScansAsOneReference) {
  // The reference made of two half-scans taken from two poses: a scan from a third pose matches it.
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const Pose2D first(0.0, 0.0, 0.0), second(0.3, 0.1, 0.2), truth(0.15, 0.05, 0.1);
  hglasm::ReferencePoints reference;
  reference.append(hglasm_test::simulateScan(world, first, laser).points, Pose2D());
  reference.append(hglasm_test::simulateScan(world, second, laser).points, second);
  Mbicp mbicp;
  mbicp.setReference(reference);
  expectExact(mbicp.match(hglasm_test::simulateScan(world, truth, laser), Pose2D()), truth);
}

TEST(Mbicp, RobustWeightsKeepAnObjectThatMovedNextToAWallFromPullingThePose) {
  // In the new scan a box (a person, a cart) stands 8 cm in front of a wall where the reference saw the
  // wall: its points lie within the association gate. Weighted by their distance they barely vote;
  // unweighted (robust_scale 0) they pull the scan towards the wall.
  const auto laser = hglasm_test::fullCircleLaser(720);
  const Pose2D truth(0.1, -0.05, 0.03);
  auto world = hglasm_test::room();
  Mbicp robust, plain([] {
    hglasm::MbicpOptions options;
    options.robust_scale = 0.0;
    return options;
  }());
  robust.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  plain.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  hglasm_test::addBox(&world, 5.92, -1.5, 0.04, 1.2);  // along the wall x = 6, 4..12 cm in front of it
  const hglasm::Scan scan = hglasm_test::simulateScan(world, truth, laser);
  const MbicpResult weighted = robust.match(scan, Pose2D()), unweighted = plain.match(scan, Pose2D());
  expectSane(weighted);
  const double weighted_error = hglasm_test::translationError(weighted.pose, truth);
  const double unweighted_error = hglasm_test::translationError(unweighted.pose, truth);
  EXPECT_LT(weighted_error, 0.004) << describe(weighted);
  EXPECT_GT(unweighted_error, 2.0 * weighted_error) << describe(unweighted);
}

TEST(Mbicp, AnIsolatedFarPointDoesNotTurnTheScanByWhereInItsBeamItWasSampled) {
  // A wall 2 m to the side seen every degree, and a post 8 m ahead. In the new scan (truth: the identity)
  // the laser sampled the post 4 cm to the side of where the reference did, well within the 14 cm its
  // 1-degree beam covers there. Point-to-point, that residual turns the scan (the wall resists only
  // through its lever arm); weighed against the beam spacing it counts by 1e-4 / (1e-4 + 0.14^2 / 12).
  hglasm::Scan reference, scan;
  for (int bearing = 40; bearing <= 140; ++bearing) {
    const double angle = bearing * M_PI / 180.0;
    reference.points.emplace_back(2.0 / std::tan(angle), 2.0);
  }
  scan.points = reference.points;
  reference.points.emplace_back(8.0, 0.0);
  scan.points.emplace_back(8.0, 0.04);
  const auto turn = [&](double point_noise) {
    hglasm::MbicpOptions options;
    options.point_noise = point_noise;
    Mbicp mbicp(options);
    mbicp.setReference(reference);
    const MbicpResult result = mbicp.match(scan, Pose2D());
    expectSane(result);
    return std::abs(result.pose.theta);
  };
  const double modelled = turn(0.01), point_to_point = turn(0.0);
  EXPECT_LT(modelled, 0.25 * point_to_point) << modelled << " vs " << point_to_point;
  EXPECT_GT(point_to_point, deg(0.01)) << "the scenario must be able to turn the scan";
}

}  // namespace

namespace {

TEST(Mbicp, ExtendingTheReferenceGivesWhatARebuildGives) {
  // Three keyframes of a room in one frame: given at once, or the first two and then the third appended.
  const hglasm_test::World world = hglasm_test::room();
  const LaserSpec laser = hglasm_test::halfCircleLaser();
  hglasm::ReferencePoints first_two, all;
  const Pose2D poses[3] = {Pose2D(0.0, 0.0, 0.0), Pose2D(0.4, 0.1, 0.2), Pose2D(0.8, -0.1, -0.3)};
  for (int k = 0; k < 3; ++k) {
    const Scan scan = hglasm_test::simulateScan(world, poses[k], laser);
    if (k < 2) first_two.append(scan.points, poses[k]);
    all.append(scan.points, poses[k]);
  }
  Mbicp rebuilt, extended;
  rebuilt.setReference(all);
  extended.setReference(first_two);
  extended.extendReference(all, 2);
  const Scan scan = hglasm_test::simulateScan(world, Pose2D(0.5, 0.0, 0.1), laser);
  for (const Pose2D& initial : {Pose2D(0.45, 0.03, 0.08), Pose2D(0.6, -0.05, 0.15)}) {
    const MbicpResult a = rebuilt.match(scan, initial);
    const MbicpResult b = extended.match(scan, initial);
    EXPECT_EQ(a.pose.x, b.pose.x);
    EXPECT_EQ(a.pose.y, b.pose.y);
    EXPECT_EQ(a.pose.theta, b.pose.theta);
    EXPECT_EQ(a.iterations, b.iterations);
    EXPECT_EQ(a.associations, b.associations);
    EXPECT_TRUE(a.covariance == b.covariance);
    expectExact(a, Pose2D(0.5, 0.0, 0.1));
  }
}

}  // namespace
