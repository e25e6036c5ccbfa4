// GLASM genetic pre-alignment: a GA over (x, y, theta) in a box centred on the odometry guess.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

/// Half-extents of the search box around the guess (by default the medium preset's, the papers' Table 1).
struct SearchBox {
  double half_x = 1.0;      ///< metres
  double half_y = 1.0;      ///< metres
  double half_theta = 1.0;  ///< radians, at most pi
};

/// The defaults are the medium preset's (presetOptions() gives the others the search space of the papers'
/// Table 1). The operators were measured with the success_ratio tool on intel and fr079 (README): strong
/// selection (a tournament of 6, 4 elites) with 10 % bit mutation and a coarse first stage find the true
/// pose more often than the textbook 2-tournament, 1 elite and 3 %.
struct GeneticOptions {
  SearchBox box;
  int population = 100;
  int generations = 10;
  int runs = 1;           ///< independent GA runs; the best result wins
  int bits_per_gene = 9;  ///< Gray-coded resolution of x, y and theta over the box
  double crossover_rate = 0.8;
  double mutation_rate = 0.10;  ///< per bit
  int tournament_size = 6;
  int elite_count = 4;  ///< best individuals copied unchanged into the next generation (at least 1)
  /// Fitness uses at most this many of the new scan's points, evenly spread over the scan (0 = all):
  /// the coarse search does not need every beam, and its cost is linear in the points.
  int max_points = 0;
  /// After the GA, a pattern search (hill climbing with halving steps) on the same fitness polishes the
  /// best pose to about a cell: the GA's resolution and few generations leave it centimetres off, and
  /// MbICP converges more reliably from closer. At most this many evaluations (0 = off).
  int polish_evaluations = 60;
  /// Coarse-to-fine: the first `coarse_generations` generations of each run score poses on the coarse
  /// table (a wide sigma, so the basin around the true pose is wide), the rest on the fine one.
  int coarse_generations = 3;
  std::uint64_t seed = 1;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, GeneticOptions* options) {
  visitor.positiveNumber("genetic/box_x", &options->box.half_x);
  visitor.positiveNumber("genetic/box_y", &options->box.half_y);
  visitor.number("genetic/box_theta", &options->box.half_theta, 0.0, M_PI, true);
  visitor.integer("genetic/population", &options->population, 2, 100000);
  visitor.positiveInteger("genetic/generations", &options->generations);
  visitor.positiveInteger("genetic/runs", &options->runs);
  visitor.integer("genetic/bits_per_gene", &options->bits_per_gene, 2, 20);
  visitor.fraction("genetic/crossover_rate", &options->crossover_rate);
  visitor.fraction("genetic/mutation_rate", &options->mutation_rate);
  visitor.positiveInteger("genetic/tournament_size", &options->tournament_size);
  visitor.integer("genetic/elite_count", &options->elite_count, 1, 100000);
  visitor.integer("genetic/max_points", &options->max_points, 0, 1000000);
  visitor.integer("genetic/polish_evaluations", &options->polish_evaluations, 0, 1000000);
  visitor.integer("genetic/coarse_generations", &options->coarse_generations, 0, 100000);
  int seed = static_cast<int>(options->seed);  // a parameter holds 32-bit ints
  visitor.integer("genetic/seed", &seed, 0, std::numeric_limits<int>::max());
  options->seed = static_cast<std::uint64_t>(seed);
}

/// Constraints between its parameters, checked once every layer is applied: "" if met, else one line
/// naming the parameter after `prefix` ("~").
std::string inconsistency(const GeneticOptions& options, const std::string& prefix);

/// How widely and how hard one alignment searches: the papers' Table 1 grows the box and the GA together.
/// All zero by default: nothing searched.
struct SearchEffort {
  SearchBox box{0.0, 0.0, 0.0};
  int population = 0;
  int generations = 0;
  int runs = 0;
  int coarse_generations = 0;
};

/// The effort of `options` itself (its box and GA size).
SearchEffort effortOf(const GeneticOptions& options);

struct PreAlignResult {
  Pose2D pose;                 ///< best pose found (new scan in the reference frame)
  std::uint32_t fitness = 0;   ///< its fitness
  double fitness_ratio = 0.0;  ///< fitness / (max cell value * points): 1 = every point on a reference point
  int evaluations = 0;         ///< fitness evaluations: 1 (guess) + population * generations * runs + polish
};

/// Scores a candidate pose of the new scan in the reference frame (higher is better).
using PoseFitness = std::function<std::uint32_t(const Pose2D&)>;

/// What one alignment maximises: the GA engine is the same whatever scores the poses (the lookup tables;
/// the evaluation's PGA, polar pairing), so comparisons at equal evaluations compare the fitness alone.
struct FitnessStages {
  PoseFitness fine;           ///< scores every pose after the coarse generations, and the guess
  PoseFitness coarse;         ///< the first coarse_generations generations (empty: none)
  double polish_step = 0.04;  ///< metres: the compass search's finest translation step
  double max_fitness = 0.0;   ///< fitness of a perfect fit (for fitness_ratio); 0: ratio 0
};

/// One chromosome of the GA and its fitness.
struct GeneticIndividual {
  std::uint64_t chromosome = 0;
  std::uint32_t fitness = 0;
};

/// The populations one alignment evolves, kept between alignments so that matching allocates nothing
/// once they have grown to the largest search's size.
struct GeneticScratch {
  std::vector<GeneticIndividual> population, offspring, best_run;
  std::vector<int> slices;
};

/// Not thread-safe per instance (it owns its random generator); separate instances are independent.
class GeneticAligner {
 public:
  explicit GeneticAligner(const GeneticOptions& options = {});

  /// Searches the box around `guess` for the pose maximising table.fitness(points, pose).
  /// If `population_out` is given it receives the final population of the best run (for display).
  /// `coarse_table` (optional) is used for the first coarse_generations generations. `effort` (optional)
  /// replaces the box and GA size of the options for this call.
  PreAlignResult align(const LookupTable& table, const std::vector<Eigen::Vector2d>& points,
                       const Pose2D& guess, std::vector<Pose2D>* population_out = nullptr,
                       const LookupTable* coarse_table = nullptr, const SearchEffort* effort = nullptr);

  /// The same GA over any fitness (see FitnessStages); the guess competes and the polish runs on `fine`.
  PreAlignResult align(const FitnessStages& stages, const Pose2D& guess,
                       std::vector<Pose2D>* population_out = nullptr, const SearchEffort* effort = nullptr);

  /// The points the fitness uses: all of them, or max_points evenly spread over the scan.
  const std::vector<Eigen::Vector2d>& fitnessSubset(const std::vector<Eigen::Vector2d>& all_points);

  /// Restarts the random sequence (same seed -> same results).
  void reseed(std::uint64_t seed) { rng_.seed(seed); }

  const GeneticOptions& options() const { return options_; }

 private:
  void polish(const PoseFitness& fitness, double finest_step, const Pose2D& guess, const SearchBox& box,
              PreAlignResult* result) const;

  GeneticOptions options_;
  std::mt19937_64 rng_;
  std::vector<Eigen::Vector2d> subset_;  // scratch: the points the fitness uses
  FitnessPoints prepared_;               // scratch: the same, prepared for the table
  GeneticScratch scratch_;
};

}  // namespace hglasm
