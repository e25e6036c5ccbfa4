// The papers' algorithms of the evaluation library: names and stages, binary GLASM's table, every
// algorithm recovering a known pose, HGLASM-g and MbICP alone result for result the odometry's ScanMatcher,
// and bad input giving a defined status with finite numbers for every one of them.
#include "hglasm_odometry/evaluation/baseline_matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "../core/bad_input_suite.h"
#include "../core/test_util.h"

namespace {

using hglasm::Algorithm;
using hglasm::BaselineMatcher;
using hglasm::LookupTable;
using hglasm::MatchResult;
using hglasm::MatchStatus;
using hglasm::Pose2D;
using hglasm::Preset;
using hglasm_test::BadInput;
using hglasm_test::deg;
using hglasm_test::describe;
using hglasm_test::expectFinite;

const std::vector<Algorithm> kEveryAlgorithm = {
    Algorithm::kHglasmG, Algorithm::kHglasmBinary, Algorithm::kGlasmG, Algorithm::kGlasmBinary,
    Algorithm::kMbicp,   Algorithm::kPga,          Algorithm::kHpga};

hglasm::BaselineOptions options(Algorithm algorithm, Preset preset, std::uint64_t seed = 1) {
  hglasm::BaselineOptions result = hglasm::baselineOptions(algorithm, preset);
  result.matcher.genetic.seed = seed;
  return result;
}

TEST(BaselineMatcher, NamesRoundTrip) {
  std::set<std::string> names;
  for (Algorithm algorithm : kEveryAlgorithm) {
    Algorithm parsed = Algorithm::kMbicp == algorithm ? Algorithm::kHglasmG : Algorithm::kMbicp;
    ASSERT_TRUE(hglasm::parseAlgorithm(hglasm::toString(algorithm), &parsed)) << hglasm::toString(algorithm);
    EXPECT_EQ(parsed, algorithm);
    names.insert(hglasm::toString(algorithm));
  }
  EXPECT_EQ(names, (std::set<std::string>{"hglasm_g", "hglasm_binary", "glasm_g", "glasm_binary", "mbicp",
                                          "pga", "hpga"}));
  Algorithm untouched = Algorithm::kGlasmG;
  EXPECT_FALSE(hglasm::parseAlgorithm("HGLASM", &untouched));
  EXPECT_FALSE(hglasm::parseAlgorithm("", &untouched));
  EXPECT_EQ(untouched, Algorithm::kGlasmG);
}

TEST(BaselineMatcher, StagesOfEachAlgorithm) {
  // (GA, MbICP, polar pairing, binary tables) per algorithm.
  const std::vector<std::vector<bool>> expected = {{true, true, false, false},  {true, true, false, true},
                                                   {true, false, false, false}, {true, false, false, true},
                                                   {false, true, false, false}, {true, false, true, false},
                                                   {true, true, true, false}};
  for (std::size_t i = 0; i < kEveryAlgorithm.size(); ++i) {
    const Algorithm algorithm = kEveryAlgorithm[i];
    EXPECT_EQ((std::vector<bool>{hglasm::usesGeneticStage(algorithm), hglasm::usesMbicpStage(algorithm),
                                 hglasm::usesPolarPairing(algorithm), hglasm::usesBinaryTables(algorithm)}),
              expected[i])
        << hglasm::toString(algorithm);
  }
}

TEST(BaselineMatcher, OptionsAreThePresetsWithPgaWithinTheTablesReach) {
  for (Preset preset : {Preset::kSmall, Preset::kMedium, Preset::kLarge}) {
    const hglasm::BaselineOptions baseline = hglasm::baselineOptions(Algorithm::kHpga, preset);
    const hglasm::MatcherOptions matcher = hglasm::presetOptions(preset);
    EXPECT_EQ(baseline.algorithm, Algorithm::kHpga);
    EXPECT_EQ(baseline.matcher.genetic.population, matcher.genetic.population);
    EXPECT_EQ(baseline.matcher.genetic.coarse_generations, matcher.genetic.coarse_generations);
    EXPECT_EQ(baseline.matcher.coarse_table.cutoff, matcher.coarse_table.cutoff);
    const hglasm::PolarPairingOptions pairing = hglasm::polarPairingOptions(baseline.matcher);
    EXPECT_EQ(pairing.pairing_threshold, matcher.table.cutoff);
    EXPECT_EQ(pairing.coarse_pairing_threshold, matcher.coarse_table.cutoff);
  }
}

TEST(BaselineMatcher, AnOverriddenTableCutoffReachesPgasPairing) {
  hglasm::BaselineOptions baseline = hglasm::baselineOptions(Algorithm::kPga, Preset::kMedium);
  baseline.matcher.table.cutoff = 0.45;
  baseline.matcher.coarse_table.cutoff = 0.9;
  const hglasm::BaselineMatcher matcher(baseline);
  EXPECT_EQ(matcher.polarPairing().options().pairing_threshold, 0.45);
  EXPECT_EQ(matcher.polarPairing().options().coarse_pairing_threshold, 0.9);
}

// ------------------------------------------------------------------ binary GLASM's table

constexpr double kCell = 0.02;
constexpr double kSigma = 0.10;
// A reference point in the middle of a cell (away from cell borders for any rounding convention).
const Eigen::Vector2d kCentre((37 + 0.5) * kCell, (-11 + 0.5) * kCell);

/// The papers' point-only table (no joining segments, no footprints).
hglasm::LookupTableOptions pointTableOptions() {
  hglasm::LookupTableOptions options;
  options.cell_size = kCell;
  options.sigma = kSigma;
  options.cutoff = 0.30;
  options.segment_max_gap = 0.0;
  options.isolated_footprint = 0.0;
  return options;
}

TEST(BinaryTable, IsASquareOfOnes) {
  LookupTable table(pointTableOptions(), hglasm::binaryKernel);
  table.build({kCentre});
  EXPECT_EQ(table.maxCellValue(), 1u);
  EXPECT_EQ(table.valueAt(kCentre), 1);
  const int half_side_cells = static_cast<int>(std::lround(kSigma / kCell));  // header: half-side sigma
  // The corners of the square are inside (a square, not a disc) ...
  for (int sx : {-1, 1}) {
    for (int sy : {-1, 1}) {
      EXPECT_EQ(table.valueAt(kCentre + kCell * Eigen::Vector2d(sx * half_side_cells, sy * half_side_cells)),
                1);
      EXPECT_EQ(table.valueAt(kCentre + kCell * Eigen::Vector2d(sx * (half_side_cells + 1), 0.0)), 0);
      EXPECT_EQ(table.valueAt(kCentre + kCell * Eigen::Vector2d(0.0, sy * (half_side_cells + 1))), 0);
    }
  }
  // ... and every cell inside holds exactly 1.
  for (int dx = -half_side_cells; dx <= half_side_cells; ++dx) {
    for (int dy = -half_side_cells; dy <= half_side_cells; ++dy) {
      ASSERT_EQ(table.valueAt(kCentre + kCell * Eigen::Vector2d(dx, dy)), 1) << dx << " " << dy;
    }
  }
}

TEST(BinaryTable, FitnessOfTheReferenceItselfIsOnePerPoint) {
  const auto scan =
      hglasm_test::simulateScan(hglasm_test::room(), Pose2D(0.1, -0.2, 0.3), hglasm_test::halfCircleLaser());
  ASSERT_GT(scan.size(), 300u);
  LookupTable binary(pointTableOptions(), hglasm::binaryKernel);
  binary.build(scan.points);
  EXPECT_EQ(binary.fitness(scan.points, Pose2D()), scan.size());
  EXPECT_EQ(binary.fitness(scan.points, Pose2D(100.0, 0.0, 0.0)), 0u);
}

TEST(BinaryTable, AlsoDrivesTheGaToAModestError) {
  // Both stamps drive the same GA: a binary table also pre-aligns a modest error.
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  LookupTable table(hglasm::LookupTableOptions(), hglasm::binaryKernel);
  table.build(hglasm_test::simulateScan(world, Pose2D(), laser).points);
  const Pose2D truth(0.15, -0.1, 0.1);
  const auto points = hglasm_test::simulateScan(world, truth, laser).points;
  hglasm::GeneticOptions genetic = hglasm::presetOptions(Preset::kMedium).genetic;
  genetic.seed = 4;
  genetic.max_points = 0;  // fitness over all points
  hglasm::GeneticAligner aligner(genetic);
  const hglasm::PreAlignResult result = aligner.align(table, points, Pose2D());
  EXPECT_LT(hglasm_test::translationError(result.pose, truth), 0.30);
  EXPECT_LT(hglasm_test::rotationError(result.pose, truth), 0.10);
  EXPECT_EQ(result.fitness, table.fitness(points, result.pose));
}

TEST(BaselineMatcher, TheBinaryAlgorithmsBuildBinaryTables) {
  const auto reference =
      hglasm_test::simulateScan(hglasm_test::room(), Pose2D(), hglasm_test::halfCircleLaser());
  for (Algorithm algorithm : kEveryAlgorithm) {
    if (!hglasm::usesGeneticStage(algorithm) || hglasm::usesPolarPairing(algorithm)) continue;
    BaselineMatcher matcher(options(algorithm, Preset::kSmall));
    matcher.setReference(reference);
    const std::uint32_t best = hglasm::usesBinaryTables(algorithm) ? 1u : 255u;
    EXPECT_EQ(matcher.table().maxCellValue(), best) << hglasm::toString(algorithm);
    EXPECT_EQ(matcher.table().valueAt(reference.points[10]), best) << hglasm::toString(algorithm);
  }
}

// ------------------------------------------------------------------ matching

MatchResult matchInRoom(const hglasm::BaselineOptions& baseline, const Pose2D& truth) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  BaselineMatcher matcher(baseline);
  matcher.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  EXPECT_TRUE(matcher.hasReference());
  return matcher.match(hglasm_test::simulateScan(world, truth, laser), Pose2D());
}

TEST(BaselineMatcher, EveryTableAlgorithmAndMbicpRecoversAKnownPose) {
  const Pose2D truth(0.18, -0.12, 0.15);  // inside the small box
  for (Algorithm algorithm : kEveryAlgorithm) {
    if (hglasm::usesPolarPairing(algorithm)) continue;  // PGA's own tests: test_polar_pairing.cpp
    SCOPED_TRACE(hglasm::toString(algorithm));
    const bool refined = hglasm::usesMbicpStage(algorithm);
    const bool genetic = hglasm::usesGeneticStage(algorithm);
    int successes = 0;
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const MatchResult result = matchInRoom(options(algorithm, Preset::kSmall, seed), truth);
      expectFinite(result);
      EXPECT_EQ(result.status, MatchStatus::kOk) << describe(result);
      // Refined: the papers' success criterion for a final result; pre-alignment alone: its own.
      const double xy_tolerance = refined ? 0.01 : 0.30;
      const double theta_tolerance = refined ? deg(0.2) : 0.10;
      if (hglasm_test::translationError(result.pose, truth) < xy_tolerance &&
          hglasm_test::rotationError(result.pose, truth) < theta_tolerance) {
        ++successes;
      } else {
        ADD_FAILURE() << "seed " << seed << ": " << describe(result);
      }
      EXPECT_EQ(result.evaluations > 0, genetic);
      EXPECT_EQ(result.prealigned_fitness > 0u, genetic);
      if (!genetic) {
        EXPECT_EQ(result.prealigned_pose.x, 0.0);  // no GA: the guess is the pre-aligned pose
        EXPECT_EQ(result.prealigned_pose.theta, 0.0);
      }
      EXPECT_EQ(result.iterations > 0, refined);
      EXPECT_EQ(result.associations > 0, refined);
      if (!refined) {
        EXPECT_EQ(result.pose.x, result.prealigned_pose.x);  // the GA's answer is final
      }
    }
    EXPECT_EQ(successes, 5);
  }
}

void expectSameResult(const MatchResult& a, const MatchResult& b) {
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.pose.x, b.pose.x);
  EXPECT_EQ(a.pose.y, b.pose.y);
  EXPECT_EQ(a.pose.theta, b.pose.theta);
  EXPECT_EQ(a.prealigned_pose.x, b.prealigned_pose.x);
  EXPECT_EQ(a.prealigned_pose.y, b.prealigned_pose.y);
  EXPECT_EQ(a.prealigned_pose.theta, b.prealigned_pose.theta);
  EXPECT_EQ(a.prealigned_fitness, b.prealigned_fitness);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.associations, b.associations);
  EXPECT_EQ(a.covariance, b.covariance);
  EXPECT_EQ(a.scan_information, b.scan_information);
}

TEST(BaselineMatcher, HglasmGAndMbicpAloneAreTheOdometrysMatcherResultForResult) {
  // success_ratio's HGLASM-g is what the odometry runs, seed for seed (and its MbICP alone, refine()).
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const hglasm::Scan reference = hglasm_test::simulateScan(world, Pose2D(), laser);
  for (Preset preset : {Preset::kSmall, Preset::kMedium, Preset::kLarge}) {
    for (const Pose2D& truth : {Pose2D(0.1, -0.05, 0.04), Pose2D(0.62, 0.45, -0.7)}) {
      SCOPED_TRACE(testing::Message() << hglasm::toString(preset) << ", truth " << truth.x);
      const hglasm::Scan scan = hglasm_test::simulateScan(world, truth, laser);
      BaselineMatcher hglasm_g(options(Algorithm::kHglasmG, preset, 5));
      BaselineMatcher mbicp(options(Algorithm::kMbicp, preset, 5));
      hglasm::ScanMatcher odometry(options(Algorithm::kHglasmG, preset, 5).matcher);
      for (int trial = 0; trial < 2; ++trial) {  // the second time round the coarse table is not rebuilt
        hglasm_g.setReference(reference);
        odometry.setReference(reference);
        mbicp.setReference(reference);
        expectSameResult(hglasm_g.match(scan, Pose2D()), odometry.match(scan, Pose2D()));
        expectSameResult(mbicp.match(scan, Pose2D(0.05, 0.0, 0.0)),
                         odometry.refine(scan, Pose2D(0.05, 0.0, 0.0)));
      }
    }
  }
}

TEST(BaselineMatcher, TheGaAloneReportsLowFitnessWhenNothingFits) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  BaselineMatcher matcher(options(Algorithm::kGlasmG, Preset::kSmall));
  matcher.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  // The new scan 50 m away from the reference: no cell of the box holds anything.
  const MatchResult far =
      matcher.match(hglasm_test::simulateScan(world, Pose2D(), laser), Pose2D(50.0, 0.0, 0.0));
  EXPECT_EQ(far.status, MatchStatus::kLowFitness) << describe(far);
  EXPECT_EQ(far.prealigned_fitness, 0u);
  expectFinite(far);
}

// ------------------------------------------------------------------ bad input

class Baseline : public hglasm_test::MatcherUnderTest {
 public:
  explicit Baseline(Algorithm algorithm) : matcher_(options(algorithm, Preset::kSmall)) {}
  void setReference(const hglasm::Scan& reference) override { matcher_.setReference(reference); }
  bool hasReference() const override { return matcher_.hasReference(); }
  MatchResult match(const hglasm::Scan& scan, const Pose2D& guess) override {
    return matcher_.match(scan, guess);
  }

 private:
  BaselineMatcher matcher_;
};

std::vector<hglasm_test::MatcherCase> baselineCases() {
  std::vector<hglasm_test::MatcherCase> cases;
  for (Algorithm algorithm : kEveryAlgorithm) {
    cases.push_back({hglasm::toString(algorithm), hglasm::usesMbicpStage(algorithm),
                     [algorithm] { return std::make_unique<Baseline>(algorithm); }});
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Baselines, BadInput, testing::ValuesIn(baselineCases()),
                         hglasm_test::matcherCaseName);

}  // namespace
