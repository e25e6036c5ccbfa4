// GLASM genetic pre-alignment: recovers known poses in each preset's box, is seeded and reproducible,
// spends the documented number of evaluations, and searches the box centred on the guess.
#include "hglasm_odometry/core/genetic_aligner.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <array>
#include <cmath>
#include <iostream>
#include <random>
#include <sstream>
#include <string>

#include "hglasm_odometry/core/scan_matcher.h"
#include "test_util.h"

namespace {

using hglasm::GeneticAligner;
using hglasm::GeneticOptions;
using hglasm::LookupTable;
using hglasm::Pose2D;
using hglasm::PreAlignResult;
using hglasm_test::LaserSpec;

// The papers' success criterion of the pre-alignment alone.
constexpr double kPrealignXy = 0.30;
constexpr double kPrealignTheta = 0.10;

bool prealigned(const Pose2D& estimate, const Pose2D& truth) {
  return hglasm_test::translationError(estimate, truth) < kPrealignXy &&
         hglasm_test::rotationError(estimate, truth) < kPrealignTheta;
}

/// A reference scan taken at the world origin and its graded table; new scans are taken at `truth` (in
/// the world, which is then also the reference frame).
class RoomFixture {
 public:
  explicit RoomFixture(const LaserSpec& laser)
      : world_(hglasm_test::room()),
        laser_(laser),
        coarse_table_(hglasm::presetOptions(hglasm::Preset::kLarge).coarse_table) {
    reference_ = hglasm_test::simulateScan(world_, Pose2D(), laser_);
    table_.build(reference_.points);
    coarse_table_.build(reference_.points);
  }
  hglasm::Scan scanAt(const Pose2D& truth) const { return hglasm_test::simulateScan(world_, truth, laser_); }
  const LookupTable& table() const { return table_; }
  /// The presets' coarse table, for their first `coarse_generations` generations (as ScanMatcher does).
  const LookupTable* coarse() const { return &coarse_table_; }

 private:
  hglasm_test::World world_;
  LaserSpec laser_;
  LookupTable table_;
  LookupTable coarse_table_;
  hglasm::Scan reference_;
};

GeneticOptions presetGenetic(hglasm::Preset preset, std::uint64_t seed) {
  GeneticOptions options = hglasm::presetOptions(preset).genetic;
  options.seed = seed;
  return options;
}

/// Runs `trials` recoveries of random poses within `fraction` of the preset's box; returns the successes
/// and describes the misses in *misses.
int recoveries(hglasm::Preset preset, const LaserSpec& laser, int trials, double fraction,
               std::string* misses) {
  const RoomFixture room(laser);
  const GeneticOptions options = presetGenetic(preset, 1);
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int successes = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const Pose2D truth(fraction * options.box.half_x * unit(rng), fraction * options.box.half_y * unit(rng),
                       fraction * options.box.half_theta * unit(rng));
    GeneticOptions seeded = options;
    seeded.seed = 100 + trial;
    GeneticAligner aligner(seeded);
    const auto scan = room.scanAt(truth);
    const PreAlignResult result = aligner.align(room.table(), scan.points, Pose2D(), nullptr, room.coarse());
    EXPECT_TRUE(result.pose.isFinite());
    if (prealigned(result.pose, truth)) {
      ++successes;
    } else {
      std::ostringstream text;
      text << "\n  trial " << trial << ": truth " << truth.x << " " << truth.y << " " << truth.theta
           << ", found " << result.pose.x << " " << result.pose.y << " " << result.pose.theta
           << " (fitness ratio " << result.fitness_ratio << ")";
      *misses += text.str();
    }
  }
  return successes;
}

TEST(GeneticAligner, SmallPresetRecoversPosesInItsBox) {
  std::string misses;
  const int successes = recoveries(hglasm::Preset::kSmall, hglasm_test::halfCircleLaser(), 50, 0.9, &misses);
  EXPECT_GE(successes, 45) << misses;
  std::cout << "[ info     ] " << hglasm::toString(hglasm::Preset::kSmall) << ": " << successes
            << "/50 pre-aligned" << misses << "\n";
}

TEST(GeneticAligner, MediumPresetRecoversPosesInItsBox) {
  std::string misses;
  const int successes = recoveries(hglasm::Preset::kMedium, hglasm_test::halfCircleLaser(), 50, 0.9, &misses);
  EXPECT_GE(successes, 45) << misses;
  std::cout << "[ info     ] " << hglasm::toString(hglasm::Preset::kMedium) << ": " << successes
            << "/50 pre-aligned" << misses << "\n";
}

TEST(GeneticAligner, LargePresetRecoversPosesInItsBoxWith360DegreeScans) {
  std::string misses;
  const int successes = recoveries(hglasm::Preset::kLarge, hglasm_test::fullCircleLaser(), 50, 0.9, &misses);
  EXPECT_GE(successes, 45) << misses;
  std::cout << "[ info     ] " << hglasm::toString(hglasm::Preset::kLarge) << ": " << successes
            << "/50 pre-aligned" << misses << "\n";
}

TEST(GeneticAligner, LargePresetFindsAHalfTurnAcrossTheSeam) {
  const RoomFixture room(hglasm_test::fullCircleLaser());
  for (double theta : {hglasm_test::deg(179.0), hglasm_test::deg(-178.0), hglasm_test::kPi}) {
    const Pose2D truth(0.8, -0.6, theta);
    GeneticAligner aligner(presetGenetic(hglasm::Preset::kLarge, 5));
    const PreAlignResult result =
        aligner.align(room.table(), room.scanAt(truth).points, Pose2D(), nullptr, room.coarse());
    EXPECT_TRUE(prealigned(result.pose, truth)) << "theta " << theta << " found " << result.pose.x << " "
                                                << result.pose.y << " " << result.pose.theta;
  }
}

TEST(GeneticAligner, FitnessAndRatioDescribeTheReturnedPose) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.1, 0.2, -0.1));
  GeneticOptions options = presetGenetic(hglasm::Preset::kSmall, 3);
  options.max_points = 0;  // fitness over all points
  GeneticAligner aligner(options);
  const PreAlignResult result = aligner.align(room.table(), scan.points, Pose2D());
  EXPECT_EQ(result.fitness, room.table().fitness(scan.points, result.pose));
  EXPECT_NEAR(result.fitness_ratio, result.fitness / (255.0 * scan.size()), 1e-12);
  EXPECT_GT(result.fitness_ratio, 0.5);
  EXPECT_LE(result.fitness_ratio, 1.0);
}

TEST(GeneticAligner, EveryGenerationCoarseStillReportsTheFineFitness) {
  // With coarse_generations == generations no generation is scored on the fine table: the final
  // population's coarse scores must not compete with the guess's fine one, nor be reported.
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.1, 0.2, -0.1));
  for (int generations : {1, 3, 6}) {
    GeneticOptions options = presetGenetic(hglasm::Preset::kSmall, 3);
    options.max_points = 0;  // fitness over all points
    options.generations = generations;
    options.coarse_generations = generations;
    GeneticAligner aligner(options);
    const PreAlignResult result = aligner.align(room.table(), scan.points, Pose2D(), nullptr, room.coarse());
    EXPECT_EQ(result.fitness, room.table().fitness(scan.points, result.pose))
        << generations << " generations";
    EXPECT_NEAR(result.fitness_ratio, result.fitness / (255.0 * scan.size()), 1e-12);
    EXPECT_LE(result.fitness_ratio, 1.0);
  }
}

TEST(GeneticAligner, SameSeedGivesIdenticalResults) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.5, -0.3, 0.6));
  GeneticAligner first(presetGenetic(hglasm::Preset::kMedium, 42));
  GeneticAligner second(presetGenetic(hglasm::Preset::kMedium, 42));
  std::vector<Pose2D> population_a, population_b;
  const PreAlignResult a = first.align(room.table(), scan.points, Pose2D(), &population_a);
  const PreAlignResult b = second.align(room.table(), scan.points, Pose2D(), &population_b);
  EXPECT_EQ(a.pose.x, b.pose.x);
  EXPECT_EQ(a.pose.y, b.pose.y);
  EXPECT_EQ(a.pose.theta, b.pose.theta);
  EXPECT_EQ(a.fitness, b.fitness);
  EXPECT_EQ(a.evaluations, b.evaluations);
  ASSERT_EQ(population_a.size(), population_b.size());
  for (std::size_t i = 0; i < population_a.size(); ++i) {
    EXPECT_EQ(population_a[i].x, population_b[i].x);
    EXPECT_EQ(population_a[i].theta, population_b[i].theta);
  }
  // reseed() restarts the sequence: the first aligner repeats its first answer.
  first.reseed(42);
  const PreAlignResult again = first.align(room.table(), scan.points, Pose2D());
  EXPECT_EQ(again.pose.x, a.pose.x);
  EXPECT_EQ(again.pose.theta, a.pose.theta);
  EXPECT_EQ(again.fitness, a.fitness);
}

TEST(GeneticAligner, DifferentSeedsGiveDifferentPopulations) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.5, -0.3, 0.6));
  std::vector<std::vector<Pose2D>> populations;
  for (std::uint64_t seed : {1, 2, 3}) {
    GeneticAligner aligner(presetGenetic(hglasm::Preset::kMedium, seed));
    std::vector<Pose2D> population;
    aligner.align(room.table(), scan.points, Pose2D(), &population);
    ASSERT_EQ(population.size(), 100u);
    populations.push_back(population);
  }
  auto identical = [](const std::vector<Pose2D>& a, const std::vector<Pose2D>& b) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i].x != b[i].x || a[i].y != b[i].y || a[i].theta != b[i].theta) return false;
    }
    return true;
  };
  EXPECT_FALSE(identical(populations[0], populations[1]));
  EXPECT_FALSE(identical(populations[0], populations[2]));
  EXPECT_FALSE(identical(populations[1], populations[2]));
}

TEST(GeneticAligner, EvaluationsArePopulationTimesGenerationsTimesRuns) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.1, 0.1, 0.1));
  auto evaluations = [&](int population, int generations, int runs) {
    GeneticOptions options;
    options.population = population;
    options.generations = generations;
    options.runs = runs;
    GeneticAligner aligner(options);
    return aligner.align(room.table(), scan.points, Pose2D()).evaluations;
  };
  const int polish = GeneticOptions().polish_evaluations;
  for (const auto& size :
       std::vector<std::array<int, 3>>{{20, 6, 1}, {100, 10, 1}, {200, 12, 2}, {40, 6, 3}}) {
    const int budget = size[0] * size[1] * size[2];
    const int spent = evaluations(size[0], size[1], size[2]);
    // Header: 1 (the guess) + population * generations * runs + at most polish_evaluations. Elitism may
    // save one evaluation per generation: at least 90 % of the GA budget.
    EXPECT_LE(spent, 1 + budget + polish) << size[0] << "x" << size[1] << "x" << size[2];
    EXPECT_GE(spent, 0.9 * budget) << size[0] << "x" << size[1] << "x" << size[2];
  }
  EXPECT_NEAR(evaluations(100, 10, 2) - evaluations(100, 10, 1), 1000.0, 0.1 * 1000.0 + polish);
}

/// Failures (empty if `pose` lies in the box of half-extents `box` around `guess`).
std::string outsideBox(const Pose2D& pose, const Pose2D& guess, const hglasm::SearchBox& box) {
  std::ostringstream text;
  const double dx = pose.x - guess.x, dy = pose.y - guess.y;
  const double dtheta = hglasm_test::angleDiff(pose.theta, guess.theta);
  if (std::abs(dx) > box.half_x + 1e-9 || std::abs(dy) > box.half_y + 1e-9 ||
      std::abs(dtheta) > box.half_theta + 1e-9) {
    text << "offset from the guess " << dx << " " << dy << " " << dtheta << " outside the box " << box.half_x
         << " " << box.half_y << " " << box.half_theta;
  }
  return text.str();
}

TEST(GeneticAligner, PopulationStaysInTheBoxAroundTheGuess) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.9, 0.0, 0.0));  // outside every box below
  const GeneticOptions options = presetGenetic(hglasm::Preset::kSmall, 9);
  for (const Pose2D& guess : {Pose2D(), Pose2D(-0.5, 0.4, 0.0), Pose2D(0.2, -0.3, 0.0)}) {
    GeneticAligner aligner(options);
    std::vector<Pose2D> population;
    aligner.align(room.table(), scan.points, guess, &population);
    ASSERT_EQ(population.size(), static_cast<std::size_t>(options.population));
    for (const Pose2D& pose : population) EXPECT_EQ(outsideBox(pose, guess, options.box), "");
  }
}

TEST(GeneticAligner, FirstGenerationIsALatinHypercubeOfTheBox) {
  // One generation: the population returned is the initial one. Cut each gene's range (2^bits levels, the
  // box end to end) into one slice per individual: each slice holds one individual, so the i-th smallest
  // level of every gene lies in slice i (the levels at a slice's edges belong to both neighbours).
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.1, 0.0, 0.0));
  GeneticOptions options;
  options.box = {0.8, 0.5, 0.6};
  options.population = 40;
  options.generations = 1;
  options.runs = 1;
  options.polish_evaluations = 0;
  const Pose2D guess(0.3, -0.2, 0.1);
  GeneticAligner aligner(options);
  std::vector<Pose2D> population;
  aligner.align(room.table(), scan.points, guess, &population);
  ASSERT_EQ(population.size(), static_cast<std::size_t>(options.population));
  const double half_widths[3] = {options.box.half_x, options.box.half_y, options.box.half_theta};
  const long levels = 1L << options.bits_per_gene;
  const long size = options.population;
  for (int gene = 0; gene < 3; ++gene) {
    std::vector<long> gene_levels;
    for (const Pose2D& pose : population) {
      const double offset = gene == 0   ? pose.x - guess.x
                            : gene == 1 ? pose.y - guess.y
                                        : pose.theta - guess.theta;
      gene_levels.push_back(
          std::lround((offset + half_widths[gene]) / (2.0 * half_widths[gene]) * (levels - 1)));
    }
    std::sort(gene_levels.begin(), gene_levels.end());
    for (long i = 0; i < size; ++i) {
      EXPECT_GE(gene_levels[i], i * levels / size) << "gene " << gene << ", slice " << i;
      EXPECT_LE(gene_levels[i], (i + 1) * levels / size) << "gene " << gene << ", slice " << i;
    }
  }
}

TEST(GeneticAligner, ResultStaysInTheBoxAroundTheGuess) {
  // The box is the search space (Table 1): the pre-aligned pose must come from it, even when the fitness
  // rises outside it (here the true pose is 0.9 m away, outside every box).
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.9, 0.0, 0.0));
  const GeneticOptions options = presetGenetic(hglasm::Preset::kSmall, 9);
  for (const Pose2D& guess : {Pose2D(), Pose2D(-0.5, 0.4, 0.0), Pose2D(0.2, -0.3, 0.0)}) {
    GeneticAligner aligner(options);
    const PreAlignResult result = aligner.align(room.table(), scan.points, guess);
    EXPECT_EQ(outsideBox(result.pose, guess, options.box), "")
        << "guess " << guess.x << " " << guess.y << ": result " << result.pose.x << " " << result.pose.y
        << " " << result.pose.theta;
  }
  // A rotated guess: whichever way the box is aligned, it stays within its half-diagonal.
  const Pose2D rotated_guess(0.3, 0.1, 2.0);
  GeneticAligner aligner(options);
  std::vector<Pose2D> population;
  const PreAlignResult result = aligner.align(room.table(), scan.points, rotated_guess, &population);
  population.push_back(result.pose);
  for (const Pose2D& pose : population) {
    EXPECT_LE(hglasm_test::translationError(pose, rotated_guess), std::hypot(0.3, 0.3) + 1e-9);
    EXPECT_LE(hglasm_test::rotationError(pose, rotated_guess), 0.3 + 1e-9);
  }
}

TEST(GeneticAligner, TheBoxIsCentredOnTheGuess) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const Pose2D truth(0.8, 0.3, 0.25);
  const auto scan = room.scanAt(truth);
  int found_near_guess = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    // Around the origin the truth is out of the small box (x: 0.8 > 0.3): it cannot be found ...
    GeneticAligner from_origin(presetGenetic(hglasm::Preset::kSmall, seed));
    const PreAlignResult far = from_origin.align(room.table(), scan.points, Pose2D());
    EXPECT_FALSE(prealigned(far.pose, truth))
        << "seed " << seed << ": found " << far.pose.x << " " << far.pose.y << " " << far.pose.theta;
    // ... but around a guess 0.2 m / 0.1 rad off it is inside the box, and found.
    GeneticAligner from_guess(presetGenetic(hglasm::Preset::kSmall, seed));
    const PreAlignResult near = from_guess.align(room.table(), scan.points, Pose2D(0.65, 0.15, 0.15));
    if (prealigned(near.pose, truth)) ++found_near_guess;
  }
  EXPECT_GE(found_near_guess, 4);
}

TEST(GeneticAligner, EmptyInputsGiveFiniteResults) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  GeneticAligner aligner(presetGenetic(hglasm::Preset::kSmall, 1));
  const PreAlignResult no_points = aligner.align(room.table(), {}, Pose2D(0.1, 0.2, 0.3));
  EXPECT_TRUE(no_points.pose.isFinite());
  EXPECT_EQ(no_points.fitness, 0u);
  EXPECT_EQ(no_points.fitness_ratio, 0.0);
  const LookupTable empty_table;
  const PreAlignResult no_table = aligner.align(empty_table, room.scanAt(Pose2D()).points, Pose2D());
  EXPECT_TRUE(no_table.pose.isFinite());
  EXPECT_EQ(no_table.fitness, 0u);
  EXPECT_TRUE(std::isfinite(no_table.fitness_ratio));
}

TEST(GeneticAligner, DegenerateOptionsDoNotCrash) {
  const RoomFixture room(hglasm_test::halfCircleLaser());
  const auto scan = room.scanAt(Pose2D(0.1, 0.0, 0.0));
  GeneticOptions options;
  options.population = 1;
  options.generations = 0;
  options.runs = 0;
  options.bits_per_gene = 40;
  options.box = {0.0, -1.0, 10.0};
  options.tournament_size = 0;
  GeneticAligner aligner(options);
  const PreAlignResult result = aligner.align(room.table(), scan.points, Pose2D());
  EXPECT_TRUE(result.pose.isFinite());
  EXPECT_TRUE(std::isfinite(result.fitness_ratio));
}

}  // namespace
