// The leap test: the two hypotheses' priors, when the prediction is in doubt, and the competition of the
// match near the prediction with the wide search's, on a room whose scan is judged where it was taken.
#include "hglasm_odometry/core/leap_detector.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hglasm_odometry/core/covariance.h"
#include "hglasm_odometry/core/search_sizing.h"
#include "test_util.h"

namespace {

using hglasm::LeapDetector;
using hglasm::LeapHypotheses;
using hglasm::LeapVerdict;
using hglasm::LogPosteriors;
using hglasm::MatchCandidate;
using hglasm::Pose2D;

/// A room scanned from the origin: the map is the scan itself, so the truth is the identity.
struct Room {
  hglasm::Scan scan =
      hglasm_test::simulateScan(hglasm_test::room(), Pose2D(), hglasm_test::fullCircleLaser());
  hglasm::LookupTable table;
  Room() { table.build(scan.points); }
  hglasm::ScanJudge judge() const { return hglasm::ScanJudge(table, scan, 100.0 / scan.size(), 0.1); }
};

const Eigen::Vector3d kBoxVariances = hglasm::boxVariances(hglasm::SearchBox{1.0, 1.0, 1.0}, 4.0);

/// A match at `pose` (a confident scan) judged against the prediction `h`.
MatchCandidate candidateAt(const Pose2D& pose, const LeapHypotheses& h, const hglasm::ScanJudge& judge) {
  MatchCandidate candidate;
  candidate.match.pose = candidate.match.scan_only_pose = pose;
  candidate.match.status = hglasm::MatchStatus::kOk;
  candidate.match.scan_information = Eigen::Vector3d(1e4, 1e4, 1e5).asDiagonal();
  candidate.match.covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal();
  candidate.match.prealign_ms = 1.0;
  candidate.match.evaluations = 100;
  const Eigen::Vector3d offset = hglasm::poseDifference(pose, h.prior.mean);
  candidate.mahalanobis_sq = offset.dot(h.prior.information * offset);
  candidate.fitness_ratio = judge.fitnessRatio(pose);
  candidate.acceptable = candidate.fitness_ratio >= 0.15;
  return candidate;
}

/// Variances of wheels sure of themselves: (x, y, theta).
const Eigen::Vector3d kConfidentWheels(1e-3, 1e-3, 1e-4);

/// The hypotheses of wheels that put the robot 0.4 m ahead of where it is (the room's origin), with
/// `variances` of (x, y, theta).
LeapHypotheses wheelsOff(const LeapDetector& detector, const Eigen::Vector3d& variances) {
  return detector.hypotheses(Pose2D(0.4, 0.0, 0.0), variances.asDiagonal(), kBoxVariances);
}

TEST(LeapDetector, TheWrongHypothesisIsWiderAndItsOddsFollowTheLastScan) {
  LeapDetector detector;
  const Eigen::Matrix3d covariance = Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal();
  LeapHypotheses h = detector.hypotheses(Pose2D(1.0, 2.0, 0.3), covariance, kBoxVariances);
  EXPECT_EQ(h.prior.mean.x, 1.0);
  EXPECT_TRUE(h.prior.information.isApprox(hglasm::informationOf(covariance)));
  EXPECT_TRUE(h.wide_covariance.isApprox(covariance + kBoxVariances.asDiagonal().toDenseMatrix()));
  EXPECT_EQ(h.wide_prior.mean.y, 2.0);
  EXPECT_DOUBLE_EQ(h.wrong_probability, 1e-3) << "leap/probability";
  // A scan whose prediction was surely wrong: the next one's is wrong with leap/persistence.
  const Room room;
  MatchCandidate nothing;
  const LeapVerdict verdict = detector.test(room.judge(), h, true, nothing, [&] {
    MatchCandidate truth = candidateAt(Pose2D(), h, room.judge());
    return truth;
  });
  ASSERT_TRUE(verdict.wide);
  EXPECT_GT(verdict.wrong_probability, 0.999);
  EXPECT_DOUBLE_EQ(detector.wrongPrior(), 1e-3) << "testing changes nothing";
  detector.remember(verdict, false);
  EXPECT_EQ(detector.wrongProbability(), verdict.wrong_probability);
  EXPECT_NEAR(detector.wrongPrior(), 0.5, 1e-3);
  detector.reset();
  EXPECT_DOUBLE_EQ(detector.wrongPrior(), 1e-3);
}

TEST(LeapDetector, APredictionIsInDoubtWhenTheMatchOrTheScanAloneLeavesIt) {
  const Room room;
  const LeapDetector detector;
  const LeapHypotheses h =
      detector.hypotheses(Pose2D(), Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal(), kBoxVariances);
  hglasm::FitnessMonitor fitness(4.0);
  MatchCandidate near = candidateAt(Pose2D(0.005, 0.0, 0.0), h, room.judge());
  ASSERT_TRUE(near.acceptable);
  EXPECT_FALSE(detector.inDoubt(near, h, fitness));
  MatchCandidate far = candidateAt(Pose2D(0.2, 0.0, 0.0), h, room.judge());
  EXPECT_TRUE(detector.inDoubt(far, h, fitness)) << "20 sigma from the prediction";
  MatchCandidate scan_left = near;
  scan_left.match.scan_only_pose = Pose2D(0.2, 0.0, 0.0);
  EXPECT_TRUE(detector.inDoubt(scan_left, h, fitness)) << "the scan alone puts it elsewhere";
  MatchCandidate unacceptable = near;
  unacceptable.acceptable = false;
  EXPECT_TRUE(detector.inDoubt(unacceptable, h, fitness));
  for (int i = 0; i < 10; ++i) fitness.add(0.99);
  MatchCandidate poor = near;
  poor.fitness_ratio = 0.5;
  EXPECT_TRUE(detector.inDoubt(poor, h, fitness)) << "fits far worse than matches usually do";
}

TEST(LeapDetector, ScoresPreferTheHypothesisWhosePriorHoldsTheMatch) {
  const Room room;
  const LeapDetector detector;
  const LeapHypotheses h =
      detector.hypotheses(Pose2D(), Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal(), kBoxVariances);
  const LogPosteriors at_prediction =
      detector.logPosteriors(room.judge(), h, candidateAt(Pose2D(), h, room.judge()).match);
  EXPECT_GT(at_prediction.prediction_holds, at_prediction.prediction_wrong);
  EXPECT_LT(at_prediction.wrongProbability(), 1e-3);
  const Pose2D away(0.3, 0.0, 0.0);
  const LogPosteriors far = detector.logPosteriors(room.judge(), h, candidateAt(away, h, room.judge()).match);
  EXPECT_LT(far.prediction_holds, far.prediction_wrong);
  EXPECT_GT(far.wrongProbability(), 0.5);
  // The prediction itself: its prior density there and its posterior volume (the prior's) cancel.
  const hglasm::ScanJudge judge = room.judge();
  EXPECT_NEAR(detector.predictionLogPosterior(judge, h),
              judge.logLikelihood(Pose2D()) + judge.freeSpaceLogLikelihood(Pose2D()) +
                  std::log1p(-h.wrong_probability),
              1e-9);
}

TEST(LeapDetector, WithoutDoubtTheTightMatchStandsAndConfirmsThePrediction) {
  const Room room;
  LeapDetector detector;
  const LeapHypotheses h =
      detector.hypotheses(Pose2D(), Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal(), kBoxVariances);
  const MatchCandidate tight = candidateAt(Pose2D(0.002, 0.0, 0.0), h, room.judge());
  const LeapVerdict verdict = detector.test(room.judge(), h, true, tight, nullptr);
  EXPECT_FALSE(verdict.doubted);
  EXPECT_FALSE(verdict.wide);
  EXPECT_EQ(verdict.chosen.match.pose.x, 0.002);
  EXPECT_LT(verdict.wrong_probability, h.wrong_probability) << "the match confirmed the prediction";
  // Uninformative (no fusion, no prediction): no posterior is formed, the prior odds stand.
  const LeapVerdict flat = detector.test(room.judge(), h, false, tight, nullptr);
  EXPECT_EQ(flat.wrong_probability, h.wrong_probability);
}

TEST(LeapDetector, AWideMatchWithTheEvidenceLeapsAndBothSearchesAreCounted) {
  // The wheels put the robot 0.4 m from where it is: the match near them fits poorly, the wide one fits.
  const Room room;
  LeapDetector detector;
  const LeapHypotheses h = wheelsOff(detector, kConfidentWheels);
  const MatchCandidate tight = candidateAt(Pose2D(0.38, 0.0, 0.0), h, room.judge());
  int searches = 0;
  const LeapVerdict verdict = detector.test(room.judge(), h, true, tight, [&] {
    ++searches;
    return candidateAt(Pose2D(), h, room.judge());
  });
  EXPECT_EQ(searches, 1);
  EXPECT_TRUE(verdict.doubted);
  EXPECT_TRUE(verdict.wide);
  EXPECT_TRUE(verdict.leapt) << "far beyond 4 sigma";
  EXPECT_FALSE(verdict.rejected);
  EXPECT_EQ(verdict.chosen.match.pose.x, 0.0);
  EXPECT_EQ(verdict.chosen.match.prealign_ms, 2.0);
  EXPECT_EQ(verdict.chosen.match.evaluations, 200);
  EXPECT_GT(verdict.wrong_probability, 0.5);
}

TEST(LeapDetector, AWideMatchWithoutTheEvidenceIsRejected) {
  // The wheels are right; the wide search found a worse fit far away.
  const Room room;
  LeapDetector detector;
  const LeapHypotheses h =
      detector.hypotheses(Pose2D(), Eigen::Vector3d(1e-3, 1e-3, 1e-4).asDiagonal(), kBoxVariances);
  const MatchCandidate tight = candidateAt(Pose2D(0.01, 0.0, 0.0), h, room.judge());
  MatchCandidate wide = candidateAt(Pose2D(0.5, 0.3, 0.2), h, room.judge());
  wide.acceptable = true;  // acceptable by the fitness floor, but a worse fit
  const LeapVerdict verdict = detector.test(room.judge(), h, true, tight, [&] { return wide; });
  EXPECT_TRUE(verdict.doubted);
  EXPECT_FALSE(verdict.wide);
  EXPECT_FALSE(verdict.leapt);
  EXPECT_TRUE(verdict.rejected);
  EXPECT_EQ(verdict.chosen.match.pose.x, 0.01);
  EXPECT_EQ(verdict.chosen.match.evaluations, 200) << "the wide search's cost counts too";
  EXPECT_LT(verdict.wrong_probability, 0.5);
}

TEST(LeapDetector, AFarWideMatchWhoseRefinementDidNotConvergeCannotLeap) {
  // The wide match of the leap above, but MbICP hit its iteration limit there: no mode of the posterior,
  // so no evidence to weigh. Near the prediction the same match may still win (it is no leap).
  const Room room;
  LeapDetector detector;
  const LeapHypotheses h = wheelsOff(detector, kConfidentWheels);
  const MatchCandidate tight = candidateAt(Pose2D(0.38, 0.0, 0.0), h, room.judge());
  MatchCandidate wide = candidateAt(Pose2D(), h, room.judge());
  wide.match.status = hglasm::MatchStatus::kMbicpNotConverged;
  ASSERT_TRUE(wide.acceptable);
  ASSERT_TRUE(detector.far(wide));
  const LeapVerdict verdict = detector.test(room.judge(), h, true, tight, [&] { return wide; });
  EXPECT_TRUE(verdict.doubted);
  EXPECT_FALSE(verdict.wide);
  EXPECT_FALSE(verdict.leapt);
  EXPECT_TRUE(verdict.rejected);
  EXPECT_EQ(verdict.chosen.match.pose.x, 0.38);

  // Within max_mahalanobis of a prediction that fits poorly: the unconverged wide match is no leap and wins.
  const LeapHypotheses wide_prior = wheelsOff(detector, Eigen::Vector3d(0.1, 0.1, 0.01));
  MatchCandidate near = candidateAt(Pose2D(), wide_prior, room.judge());
  near.match.status = hglasm::MatchStatus::kMbicpNotConverged;
  const MatchCandidate poor = candidateAt(Pose2D(0.38, 0.0, 0.0), wide_prior, room.judge());
  ASSERT_FALSE(detector.far(near));
  const LeapVerdict near_verdict = detector.test(room.judge(), wide_prior, true, poor, [&] { return near; });
  EXPECT_TRUE(near_verdict.wide);
  EXPECT_FALSE(near_verdict.leapt);
}

TEST(LeapDetector, NothingAcceptableKeepsThePriorOdds) {
  const Room room;
  LeapDetector detector;
  const LeapHypotheses h =
      detector.hypotheses(Pose2D(), Eigen::Vector3d(1e-3, 1e-3, 1e-4).asDiagonal(), kBoxVariances);
  MatchCandidate tight = candidateAt(Pose2D(), h, room.judge());
  tight.acceptable = false;
  MatchCandidate wide = tight;
  const LeapVerdict verdict = detector.test(room.judge(), h, true, tight, [&] { return wide; });
  EXPECT_TRUE(verdict.doubted);
  EXPECT_FALSE(verdict.chosen.acceptable);
  EXPECT_EQ(verdict.wrong_probability, h.wrong_probability);
}

/// A detector that has seen `scans` scans, `faults` of them (spread evenly) with a far leap to a usual fit.
LeapDetector withHistory(int scans, int faults, const hglasm::LeapOptions& options = {}) {
  LeapDetector detector(options);
  for (int i = 0; i < scans; ++i) {
    LeapVerdict verdict;
    verdict.leapt = faults > 0 && i % (scans / faults) == 0;
    detector.remember(verdict, true);
  }
  detector.reset();  // forgets the odds of the last scan, not the wheels' record
  return detector;
}

/// The wheels put the robot `offset` (x, m) from where it is: the wide search finds the truth.
LeapVerdict slipped(const LeapDetector& detector, const Room& room, double offset) {
  const LeapHypotheses h = detector.hypotheses(Pose2D(offset, 0.0, 0.0),
                                               Eigen::Vector3d(1e-3, 1e-3, 1e-4).asDiagonal(), kBoxVariances);
  const MatchCandidate tight = candidateAt(Pose2D(offset - 0.02, 0.0, 0.0), h, room.judge());
  return detector.test(room.judge(), h, true, tight, [&] { return candidateAt(Pose2D(), h, room.judge()); });
}

TEST(LeapDetector, WheelsRarelyWrongLeapOnlyWhenTheNextScanAsksForTheSameCorrection) {
  const Room room;
  LeapDetector detector = withHistory(5000, 1);
  EXPECT_LT(detector.faultRate(), detector.options().confirm_below);
  ASSERT_TRUE(detector.confirmationRequired());
  // A first scan asks for 0.4 m: deferred, the match near the prediction stands.
  LeapVerdict first = slipped(detector, room, 0.4);
  EXPECT_TRUE(first.deferred);
  EXPECT_FALSE(first.leapt);
  EXPECT_FALSE(first.wide);
  EXPECT_NEAR(first.chosen.match.pose.x, 0.38, 1e-12);
  EXPECT_NEAR(first.correction.x, -0.4, 1e-12) << "match = correction * prediction";
  EXPECT_EQ(first.wide_fitness_ratio, room.judge().fitnessRatio(Pose2D())) << "the far place's fit";
  EXPECT_GT(first.wide_fitness_ratio, 0.5);
  detector.remember(first, false);
  // The next asks for the same: the wheels slipped, the leap is taken.
  const LeapVerdict same = slipped(detector, room, 0.4);
  EXPECT_TRUE(same.leapt);
  EXPECT_FALSE(same.deferred);
  EXPECT_EQ(same.chosen.match.pose.x, 0.0);
  // After a deferred 0.4 m, a scan asking for 0.8 m points elsewhere: deferred again.
  detector.remember(first, false);
  const LeapVerdict other = slipped(detector, room, 0.8);
  EXPECT_TRUE(other.deferred);
  EXPECT_FALSE(other.leapt);
  // With nothing deferred before, even the same correction waits.
  detector.remember(LeapVerdict(), false);
  EXPECT_TRUE(slipped(detector, room, 0.4).deferred);
}

TEST(LeapDetector, ASlipSoftensThePriorByItsPosteriorProbability) {
  // Wheels with no record yet: slip probability p = confirm_below = 1e-3, the slip component 9 times
  // wider. The prior's weight is 1 - w + w / 9 for the slip's posterior probability w at the innovation.
  const LeapDetector detector;
  ASSERT_DOUBLE_EQ(detector.faultRate(), 1e-3);
  const double k = detector.options().slip_variance_scale;
  ASSERT_EQ(k, 9.0);
  const double odds_at_zero = 1e-3 / (1.0 - 1e-3) * std::pow(k, -1.5);
  const double w0 = odds_at_zero / (1.0 + odds_at_zero);
  EXPECT_NEAR(detector.priorWeight(0.0), 1.0 - w0 + w0 / k, 1e-15);
  // Where both components are equally likely: w = 1/2.
  const double even = -2.0 * std::log(odds_at_zero) / (1.0 - 1.0 / k);
  EXPECT_NEAR(detector.priorWeight(even), 0.5 + 0.5 / k, 1e-12);
  double previous = 1.0;
  for (double q = 0.0; q <= k * 16.0; q += 1.0) {
    EXPECT_LE(detector.priorWeight(q), previous + 1e-15) << q;
    previous = detector.priorWeight(q);
  }
  EXPECT_NEAR(detector.priorWeight(k * 16.0), 1.0 / k, 1e-6) << "a slip, surely";
  // Beyond the slip component's own max_mahalanobis (4): no slip either, a prediction that says nothing.
  EXPECT_EQ(detector.priorWeight(k * 16.0 + 1e-6), 0.0);
  EXPECT_EQ(detector.priorWeight(std::nan("")), 1.0);
  // Wheels often wrong slip more readily; without the mixture the prior stays.
  const LeapDetector often = withHistory(2000, 80);
  EXPECT_LT(often.priorWeight(20.0), 0.3);
  EXPECT_GT(detector.priorWeight(20.0), 0.7);
  hglasm::LeapOptions off;
  off.slip_variance_scale = 0.0;
  EXPECT_EQ(LeapDetector(off).priorWeight(1e6), 1.0);
}

TEST(LeapDetector, TheSlipTestAllowsForTheMountInTurns) {
  // A mount known to 0.1 m moves a step that turns by a by (R(a) - I) m: variance 0.01 (2 - 2 cos a).
  const LeapDetector detector;
  EXPECT_TRUE(detector.slipCovariance(Pose2D(0.5, 0.0, 0.0)).isZero()) << "no turn, nothing";
  const Eigen::Matrix3d quarter = detector.slipCovariance(Pose2D(0.0, 0.0, M_PI / 2));
  EXPECT_NEAR(quarter(0, 0), 0.02, 1e-15);
  EXPECT_NEAR(quarter(1, 1), 0.02, 1e-15);
  EXPECT_EQ(quarter(2, 2), 0.0);
  EXPECT_EQ(quarter(0, 1), 0.0);
}

TEST(LeapDetector, WheelsOftenWrongLeapAtOnce) {
  const Room room;
  const LeapDetector detector = withHistory(2000, 80);  // 4 % of the scans, as intel's wheels do
  EXPECT_GT(detector.faultRate(), detector.options().confirm_below);
  EXPECT_FALSE(detector.confirmationRequired());
  const LeapVerdict verdict = slipped(detector, room, 0.4);
  EXPECT_TRUE(verdict.leapt);
  EXPECT_FALSE(verdict.deferred);
  // Without leap/confirm the same holds for trustworthy wheels.
  hglasm::LeapOptions options;
  options.confirm = false;
  const LeapDetector unconfirmed = withHistory(5000, 1, options);
  EXPECT_FALSE(unconfirmed.confirmationRequired());
  EXPECT_TRUE(slipped(unconfirmed, room, 0.4).leapt);
}

TEST(LeapDetector, OnlyScansThatFitAsUsualNearThePredictionCountTowardsTheWheelsRecord) {
  LeapDetector detector;
  EXPECT_DOUBLE_EQ(detector.faultRate(), detector.options().confirm_below)
      << "the rate over kTrustScans to start";
  EXPECT_FALSE(detector.confirmationRequired()) << "nothing known yet";
  LeapVerdict leapt;
  leapt.leapt = true;
  for (int i = 0; i < 100; ++i) detector.remember(leapt, false);
  EXPECT_DOUBLE_EQ(detector.faultRate(), detector.options().confirm_below)
      << "leaps where the scan fits poorly near the prediction say nothing of the wheels";
  detector.remember(LeapVerdict(), true);
  EXPECT_TRUE(detector.confirmationRequired()) << "a scan that fit as usual, and no fault";
  detector.remember(leapt, true);
  EXPECT_FALSE(detector.confirmationRequired()) << "a fault early on: the wheels are corrected at once";
  LeapVerdict deferred;
  deferred.deferred = true;
  const double before = detector.faultRate();
  detector.remember(deferred, true);
  EXPECT_GT(detector.faultRate(), before) << "a deferred leap counts as one";
}

TEST(LeapDetector, AnImusRotationIsCorrectedAtOnce) {
  const Room room;
  const LeapDetector detector = withHistory(5000, 1);
  ASSERT_TRUE(detector.confirmationRequired());
  const LeapHypotheses h = wheelsOff(detector, kConfidentWheels);
  const MatchCandidate tight = candidateAt(Pose2D(0.38, 0.0, 0.0), h, room.judge());
  const LeapVerdict verdict = detector.test(
      room.judge(), h, true, tight, [&] { return candidateAt(Pose2D(), h, room.judge()); }, false);
  EXPECT_TRUE(verdict.leapt);
  EXPECT_FALSE(verdict.deferred);
}

}  // namespace
