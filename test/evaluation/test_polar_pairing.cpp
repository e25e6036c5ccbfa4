// PGA (Martinez et al. 2006): polar pairing fitness and the GA on it, on synthetic geometry with exact
// answers.
#include "hglasm_odometry/evaluation/polar_pairing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include "../core/test_util.h"
#include "hglasm_odometry/core/genetic_aligner.h"
#include "hglasm_odometry/evaluation/baseline_matcher.h"

namespace {

using hglasm::FitnessPoints;
using hglasm::PolarPairing;
using hglasm::Pose2D;
using hglasm::ReferencePoints;
using hglasm_test::deg;

constexpr double kPrealignXy = 0.30;
constexpr double kPrealignTheta = 0.10;

ReferencePoints referenceOf(const hglasm::Scan& scan) {
  ReferencePoints reference;
  reference.append(scan.points);
  return reference;
}

/// The points of `scan` seen from a sensor at `pose` (written out by hand, not with the core's Pose2D).
std::vector<Eigen::Vector2d> seenFrom(const hglasm::Scan& scan, const Pose2D& pose) {
  const Pose2D inverse = hglasm_test::relativeByHand(pose, hglasm_test::rawPose(0, 0, 0));
  const double c = std::cos(inverse.theta), s = std::sin(inverse.theta);
  std::vector<Eigen::Vector2d> moved;
  for (const Eigen::Vector2d& p : scan.points) {
    moved.emplace_back(c * p.x() - s * p.y() + inverse.x, s * p.x() + c * p.y() + inverse.y);
  }
  return moved;
}

class PolarRoom : public ::testing::Test {
 protected:
  void build(const hglasm_test::LaserSpec& laser) {
    laser_ = laser;
    reference_scan_ = hglasm_test::simulateScan(world_, Pose2D(), laser_);
    pairing_.build(referenceOf(reference_scan_));
  }
  hglasm::Scan scanAt(const Pose2D& truth) const { return hglasm_test::simulateScan(world_, truth, laser_); }

  hglasm_test::World world_ = hglasm_test::room();
  hglasm_test::LaserSpec laser_;
  hglasm::Scan reference_scan_;
  PolarPairing pairing_;
};

TEST_F(PolarRoom, TheStepIsTheReferenceBeamSpacing) {
  build(hglasm_test::halfCircleLaser());
  EXPECT_NEAR(pairing_.angularStep(), deg(0.5), 1e-9);
  EXPECT_EQ(pairing_.stepCount(), 720u);
  // The odd beams of the same scan: twice the spacing (the protocol's reference).
  PolarPairing odd;
  odd.build(referenceOf(hglasm::selectBeams(reference_scan_, 1)));
  EXPECT_NEAR(odd.angularStep(), deg(1.0), 1e-9);
  // An explicit step wins.
  hglasm::PolarPairingOptions options;
  options.angular_step = deg(2.0);
  PolarPairing coarse(options);
  coarse.build(referenceOf(reference_scan_));
  EXPECT_DOUBLE_EQ(coarse.angularStep(), deg(2.0));
  EXPECT_EQ(coarse.stepCount(), 180u);
}

TEST_F(PolarRoom, FitnessIsMaximalExactlyAtTheTruth) {
  build(hglasm_test::halfCircleLaser());
  const Pose2D truth(0.4, -0.25, 0.15);
  FitnessPoints points;
  points.assign(seenFrom(reference_scan_, truth));  // the reference's own points: pairs at distance 0
  const double threshold = 0.30;
  const std::uint32_t best = PolarPairing::kPointScore * static_cast<std::uint32_t>(points.size());
  EXPECT_EQ(pairing_.fitness(points, truth, threshold), best);
  EXPECT_EQ(pairing_.pairedCount(points, truth, threshold), points.size());
  for (const Pose2D& offset : {Pose2D(0.02, 0, 0), Pose2D(0, -0.02, 0), Pose2D(0, 0, 0.005),
                               Pose2D(0.1, 0.1, -0.05), Pose2D(0.5, 0, 0), Pose2D(0, 0, 0.3)}) {
    const Pose2D near(truth.x + offset.x, truth.y + offset.y, truth.theta + offset.theta);
    EXPECT_LT(pairing_.fitness(points, near, threshold), best)
        << offset.x << " " << offset.y << " " << offset.theta;
  }
  // Far away nothing pairs: fitness 0.
  EXPECT_EQ(pairing_.fitness(points, Pose2D(30.0, 30.0, 0.0), threshold), 0u);
}

TEST_F(PolarRoom, PairsOnlyWithinTheThresholdAndTheSameStep) {
  build(hglasm_test::halfCircleLaser());
  // One point 0.1 m beyond the reference point of its beam (same step): paired at 0.1 m.
  const Eigen::Vector2d reference_point = reference_scan_.points[100];
  const Eigen::Vector2d beyond = reference_point * (1.0 + 0.1 / reference_point.norm());
  FitnessPoints one;
  one.assign({beyond});
  const double expected = PolarPairing::kPointScore * (1.0 - 0.01 / 0.09);
  EXPECT_NEAR(static_cast<double>(pairing_.fitness(one, Pose2D(), 0.30)), expected, 2.0);
  EXPECT_EQ(pairing_.fitness(one, Pose2D(), 0.05), 0u);  // beyond the threshold: unpaired
  // A point in a step with no reference point (behind the 180-degree laser) never pairs.
  FitnessPoints behind;
  behind.assign({Eigen::Vector2d(-2.0, 0.01)});
  EXPECT_EQ(pairing_.fitness(behind, Pose2D(), 10.0), 0u);
  EXPECT_EQ(pairing_.fitness(one, Pose2D(std::nan(""), 0, 0), 0.30), 0u);
}

TEST_F(PolarRoom, StepsWrapAtPlusMinusPiFor360DegreeScans) {
  build(hglasm_test::fullCircleLaser(360));
  EXPECT_NEAR(pairing_.angularStep(), deg(1.0), 1e-9);
  EXPECT_EQ(pairing_.stepCount(), 360u);
  // The first beam is at -pi: a point just below +pi lies in its step across the seam.
  const Eigen::Vector2d first = reference_scan_.points.front();
  const double range = first.norm();
  FitnessPoints across;
  across.assign({Eigen::Vector2d(range * std::cos(M_PI - 1e-4), range * std::sin(M_PI - 1e-4))});
  EXPECT_GT(pairing_.fitness(across, Pose2D(), 0.05), 0u);
}

TEST_F(PolarRoom, EmptyReferenceScoresNothing) {
  PolarPairing empty;
  empty.build(ReferencePoints());
  FitnessPoints points;
  points.assign({Eigen::Vector2d(1.0, 0.0)});
  EXPECT_TRUE(empty.empty());
  EXPECT_EQ(empty.fitness(points, Pose2D(), 0.3), 0u);
}

/// The GA on PGA's fitness recovers displaced room scans within the pre-alignment thresholds.
int pgaRecoveries(hglasm::Preset preset, const hglasm_test::LaserSpec& laser, int trials,
                  std::string* misses) {
  const hglasm_test::World world = hglasm_test::room();
  const hglasm::BaselineOptions baseline = hglasm::baselineOptions(hglasm::Algorithm::kPga, preset);
  const hglasm::MatcherOptions& matcher = baseline.matcher;
  PolarPairing pairing(hglasm::polarPairingOptions(matcher));
  pairing.build(referenceOf(hglasm_test::simulateScan(world, Pose2D(), laser)));
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> unit(-0.9, 0.9);
  int successes = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const hglasm::SearchBox& box = matcher.genetic.box;
    const Pose2D truth(box.half_x * unit(rng), box.half_y * unit(rng), box.half_theta * unit(rng));
    hglasm::GeneticOptions genetic = matcher.genetic;
    genetic.seed = 500 + trial;
    hglasm::GeneticAligner aligner(genetic);
    FitnessPoints points;
    points.assign(hglasm_test::simulateScan(world, truth, laser).points);
    const hglasm::PreAlignResult result =
        aligner.align(hglasm::polarPairingStages(pairing, points, matcher.table.cell_size), Pose2D());
    if (hglasm_test::translationError(result.pose, truth) < kPrealignXy &&
        hglasm_test::rotationError(result.pose, truth) < kPrealignTheta) {
      ++successes;
    } else {
      std::ostringstream text;
      text << "\n  truth " << truth.x << " " << truth.y << " " << truth.theta << ", found " << result.pose.x
           << " " << result.pose.y << " " << result.pose.theta;
      *misses += text.str();
    }
  }
  return successes;
}

TEST(PgaGeneticAligner, SmallAndMediumPresetsRecoverDisplacedRoomScans) {
  for (hglasm::Preset preset : {hglasm::Preset::kSmall, hglasm::Preset::kMedium}) {
    std::string misses;
    const int successes = pgaRecoveries(preset, hglasm_test::halfCircleLaser(), 30, &misses);
    EXPECT_GE(successes, 28) << hglasm::toString(preset) << misses;
  }
}

TEST(PgaGeneticAligner, LargePresetRecoversDisplacedRoomScansWith360DegreeScans) {
  std::string misses;
  const int successes = pgaRecoveries(hglasm::Preset::kLarge, hglasm_test::fullCircleLaser(), 15, &misses);
  EXPECT_GE(successes, 14) << misses;
}

hglasm::MatchResult matchWith(hglasm::Algorithm algorithm, std::uint64_t seed, const Pose2D& truth) {
  const hglasm_test::World world = hglasm_test::room();
  const hglasm_test::LaserSpec laser = hglasm_test::halfCircleLaser();
  hglasm::BaselineOptions options = hglasm::baselineOptions(algorithm, hglasm::Preset::kMedium);
  options.matcher.genetic.seed = seed;
  hglasm::BaselineMatcher matcher(options);
  matcher.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  return matcher.match(hglasm_test::simulateScan(world, truth, laser), Pose2D());
}

TEST(PgaBaselineMatcher, HybridRefinesToTheTruthAndIsDeterministicPerSeed) {
  const Pose2D truth(0.6, -0.4, deg(25.0));
  const hglasm::MatchResult pga = matchWith(hglasm::Algorithm::kPga, 3, truth);
  const hglasm::MatchResult hpga = matchWith(hglasm::Algorithm::kHpga, 3, truth);
  EXPECT_TRUE(pga.ok());
  EXPECT_LT(hglasm_test::translationError(pga.pose, truth), kPrealignXy);
  EXPECT_LT(hglasm_test::rotationError(pga.pose, truth), kPrealignTheta);
  EXPECT_GT(pga.prealigned_fitness_ratio, 0.5);
  EXPECT_GT(pga.evaluations, 100 * 9);
  EXPECT_EQ(hpga.iterations > 0, true);
  EXPECT_LT(hglasm_test::translationError(hpga.pose, truth), 0.01);
  EXPECT_LT(hglasm_test::rotationError(hpga.pose, truth), 0.002);
  // The hybrid's GA stage is PGA's, seed for seed.
  EXPECT_EQ(hpga.prealigned_pose.x, pga.prealigned_pose.x);
  EXPECT_EQ(hpga.prealigned_pose.theta, pga.prealigned_pose.theta);
  EXPECT_EQ(hpga.prealigned_fitness, pga.prealigned_fitness);
  // Same seed, same result; another seed, another search.
  const hglasm::MatchResult again = matchWith(hglasm::Algorithm::kPga, 3, truth);
  EXPECT_EQ(again.prealigned_pose.x, pga.prealigned_pose.x);
  EXPECT_EQ(again.prealigned_pose.y, pga.prealigned_pose.y);
  EXPECT_EQ(again.prealigned_fitness, pga.prealigned_fitness);
  EXPECT_EQ(again.evaluations, pga.evaluations);
  const hglasm::MatchResult other = matchWith(hglasm::Algorithm::kPga, 4, truth);
  EXPECT_FALSE(other.prealigned_pose.x == pga.prealigned_pose.x &&
               other.prealigned_fitness == pga.prealigned_fitness && other.evaluations == pga.evaluations);
}

TEST(PgaBaselineMatcher, AlgorithmNamesParse) {
  hglasm::Algorithm algorithm = hglasm::Algorithm::kMbicp;
  ASSERT_TRUE(hglasm::parseAlgorithm("pga", &algorithm));
  EXPECT_EQ(algorithm, hglasm::Algorithm::kPga);
  ASSERT_TRUE(hglasm::parseAlgorithm("hpga", &algorithm));
  EXPECT_EQ(algorithm, hglasm::Algorithm::kHpga);
  EXPECT_TRUE(hglasm::usesGeneticStage(hglasm::Algorithm::kPga));
  EXPECT_FALSE(hglasm::usesMbicpStage(hglasm::Algorithm::kPga));
  EXPECT_TRUE(hglasm::usesMbicpStage(hglasm::Algorithm::kHpga));
  EXPECT_TRUE(hglasm::usesPolarPairing(hglasm::Algorithm::kHpga));
  EXPECT_FALSE(hglasm::usesPolarPairing(hglasm::Algorithm::kHglasmG));
}

}  // namespace
