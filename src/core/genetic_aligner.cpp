#include "hglasm_odometry/core/genetic_aligner.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "hglasm_odometry/core/parameter_source.h"

namespace hglasm {

std::string inconsistency(const GeneticOptions& options, const std::string& prefix) {
  const auto integer = ParameterValue::ofInt;
  if (options.elite_count >= options.population) {
    return constraintError(prefix, "genetic/elite_count", "be less than", "genetic/population",
                           integer(options.population), integer(options.elite_count));
  }
  if (options.coarse_generations > options.generations) {
    return constraintError(prefix, "genetic/coarse_generations", "not exceed", "genetic/generations",
                           integer(options.generations), integer(options.coarse_generations));
  }
  if (options.tournament_size > options.population) {
    return constraintError(prefix, "genetic/tournament_size", "not exceed", "genetic/population",
                           integer(options.population), integer(options.tournament_size));
  }
  return "";
}
namespace {

std::uint64_t grayToBinary(std::uint64_t gray) {
  for (std::uint64_t shift = gray >> 1; shift; shift >>= 1) gray ^= shift;
  return gray;
}

/// Chromosome layout: three Gray-coded genes of `bits` bits each, x | y | theta (theta lowest).
class Codec {
 public:
  Codec(const SearchBox& box, const Pose2D& centre, int bits)
      : bits_(bits), mask_((std::uint64_t{1} << bits) - 1), centre_(centre) {
    const double levels = static_cast<double>(mask_);
    scale_[0] = 2.0 * box.half_x / levels;
    scale_[1] = 2.0 * box.half_y / levels;
    // A full-turn box would put -pi and +pi on two distinct genes: spread the levels over [-pi, pi).
    const double theta_span =
        box.half_theta >= M_PI ? 2.0 * M_PI * levels / (levels + 1.0) : 2.0 * box.half_theta;
    scale_[2] = theta_span / levels;
    low_[0] = -box.half_x;
    low_[1] = -box.half_y;
    low_[2] = box.half_theta >= M_PI ? -M_PI : -box.half_theta;
  }

  int totalBits() const { return 3 * bits_; }

  /// The box is centred on the guess and aligned with the reference frame's axes.
  Pose2D decode(std::uint64_t chromosome) const {
    double offset[3];
    for (int gene = 0; gene < 3; ++gene) {
      const std::uint64_t gray = (chromosome >> ((2 - gene) * bits_)) & mask_;
      offset[gene] = low_[gene] + scale_[gene] * static_cast<double>(grayToBinary(gray));
    }
    return Pose2D(centre_.x + offset[0], centre_.y + offset[1], centre_.theta + offset[2]);
  }

 private:
  int bits_;
  std::uint64_t mask_;
  Pose2D centre_;
  double scale_[3];
  double low_[3];
};

using Individual = GeneticIndividual;

/// Latin hypercube: each gene's range is cut into one slice per individual and every slice is used once,
/// so the first generation covers every heading of a +-pi box (uniform draws leave gaps that the GA then
/// has to close by mutation, and a 180-degree look-alike wins more often).
void seedLatinHypercube(int bits, std::mt19937_64& rng, std::vector<int>* slices,
                        std::vector<Individual>* population) {
  const std::uint64_t gene_levels = std::uint64_t{1} << bits;
  const std::size_t size = population->size();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (auto& individual : *population) individual.chromosome = 0;
  slices->resize(size);
  for (int gene = 0; gene < 3; ++gene) {
    std::iota(slices->begin(), slices->end(), 0);
    std::shuffle(slices->begin(), slices->end(), rng);
    for (std::size_t i = 0; i < size; ++i) {
      const double position = (static_cast<double>((*slices)[i]) + unit(rng)) / static_cast<double>(size);
      const std::uint64_t level =
          std::min(gene_levels - 1, static_cast<std::uint64_t>(position * static_cast<double>(gene_levels)));
      const std::uint64_t gray = level ^ (level >> 1);
      (*population)[i].chromosome |= gray << ((2 - gene) * bits);
    }
  }
}

}  // namespace

SearchEffort effortOf(const GeneticOptions& options) {
  SearchEffort effort;
  effort.box = options.box;
  effort.population = options.population;
  effort.generations = options.generations;
  effort.runs = options.runs;
  effort.coarse_generations = options.coarse_generations;
  return effort;
}

namespace {

/// Sizes the GA can work with whatever it was given.
SearchEffort sanitised(SearchEffort effort) {
  effort.population = std::max(2, effort.population);
  effort.generations = std::max(1, effort.generations);
  effort.runs = std::max(1, effort.runs);
  effort.coarse_generations = std::max(0, effort.coarse_generations);
  effort.box.half_theta = std::min(std::abs(effort.box.half_theta), M_PI);
  effort.box.half_x = std::abs(effort.box.half_x);
  effort.box.half_y = std::abs(effort.box.half_y);
  return effort;
}

/// The runs of one alignment: a Latin-hypercube population evolved by tournament selection, one-point
/// crossover, bit mutation and elitism, scored on the coarse fitness for the first coarse_generations
/// generations and on the fine one after. Counts every evaluation in *evaluations.
class Evolution {
 public:
  Evolution(const GeneticOptions& options, const FitnessStages& stages, const Codec& codec,
            const SearchEffort& effort, std::mt19937_64& rng, int* evaluations, GeneticScratch* scratch)
      : options_(options),
        stages_(stages),
        codec_(codec),
        generations_(effort.generations),
        coarse_generations_(stages.coarse ? effort.coarse_generations : 0),
        total_bits_(codec.totalBits()),
        population_size_(effort.population),
        elite_count_(std::clamp(options.elite_count, 1, effort.population - 1)),
        // Each bit flips with probability mutation_rate: one random byte per bit, compared with a
        // threshold (resolution 1/256).
        mutation_threshold_(
            static_cast<unsigned>(std::clamp(std::lround(options.mutation_rate * 256.0), 0L, 256L))),
        rng_(rng),
        evaluations_(evaluations),
        random_member_(0, effort.population - 1),
        random_cut_(1, codec.totalBits() - 1),
        population_(scratch->population),
        offspring_(scratch->offspring),
        slices_(scratch->slices) {
    population_.assign(static_cast<std::size_t>(population_size_), Individual{});
    offspring_.assign(static_cast<std::size_t>(population_size_), Individual{});
  }

  /// One run; its final population, scored on the fine fitness.
  const std::vector<Individual>& run() {
    scoring_ = coarse_generations_ > 0 ? &stages_.coarse : &stages_.fine;
    seedLatinHypercube(options_.bits_per_gene, rng_, &slices_, &population_);
    for (auto& individual : population_) evaluate(individual);
    for (int generation = 1; generation < generations_; ++generation) {
      if (generation == coarse_generations_) rescoreOnFine();
      breed();
    }
    // Every generation was coarse: rescore on the fine fitness, the one the guess and the polish use.
    if (scoring_ != &stages_.fine) rescoreOnFine();
    return population_;
  }

 private:
  void evaluate(Individual& individual) {
    individual.fitness = (*scoring_)(codec_.decode(individual.chromosome));
    ++*evaluations_;
  }

  void rescoreOnFine() {
    scoring_ = &stages_.fine;
    for (auto& individual : population_) evaluate(individual);
  }

  const Individual& tournament() {
    const Individual* winner = &population_[random_member_(rng_)];
    for (int k = 1; k < std::min(options_.tournament_size, population_size_); ++k) {
      const Individual& challenger = population_[random_member_(rng_)];
      if (challenger.fitness > winner->fitness) winner = &challenger;
    }
    return *winner;
  }

  /// Eight bits per 64-bit draw.
  std::uint64_t mutate(std::uint64_t chromosome) {
    std::uint64_t random_bytes = 0;
    for (int bit = 0; bit < total_bits_; ++bit) {
      if (bit % 8 == 0) random_bytes = rng_();
      if ((random_bytes & 0xFF) < mutation_threshold_) chromosome ^= std::uint64_t{1} << bit;
      random_bytes >>= 8;
    }
    return chromosome;
  }

  /// The next generation replaces the population.
  void breed() {
    // Elitism: the best individuals survive unchanged (no re-evaluation needed).
    std::partial_sort(population_.begin(), population_.begin() + elite_count_, population_.end(),
                      [](const Individual& a, const Individual& b) { return a.fitness > b.fitness; });
    std::copy(population_.begin(), population_.begin() + elite_count_, offspring_.begin());
    for (int i = elite_count_; i < population_size_; i += 2) {
      std::uint64_t child_a = tournament().chromosome;
      std::uint64_t child_b = tournament().chromosome;
      if (unit_(rng_) < options_.crossover_rate) {
        // One-point crossover on the bit string: exchange the tails below a random cut.
        const std::uint64_t tail = (std::uint64_t{1} << random_cut_(rng_)) - 1;
        const std::uint64_t swap = (child_a ^ child_b) & tail;
        child_a ^= swap;
        child_b ^= swap;
      }
      offspring_[i].chromosome = mutate(child_a);
      evaluate(offspring_[i]);
      if (i + 1 < population_size_) {
        offspring_[i + 1].chromosome = mutate(child_b);
        evaluate(offspring_[i + 1]);
      }
    }
    population_.swap(offspring_);
  }

  const GeneticOptions& options_;
  const FitnessStages& stages_;
  const Codec& codec_;
  const int generations_;
  const int coarse_generations_;
  const int total_bits_;
  const int population_size_;
  const int elite_count_;
  const unsigned mutation_threshold_;
  std::mt19937_64& rng_;
  int* evaluations_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  std::uniform_int_distribution<int> random_member_;
  std::uniform_int_distribution<int> random_cut_;
  std::vector<Individual>& population_;
  std::vector<Individual>& offspring_;
  std::vector<int>& slices_;
  const PoseFitness* scoring_ = nullptr;
};

}  // namespace

GeneticAligner::GeneticAligner(const GeneticOptions& options) : options_(options), rng_(options.seed) {
  const SearchEffort effort = sanitised(effortOf(options_));
  options_.population = effort.population;
  options_.generations = effort.generations;
  options_.runs = effort.runs;
  options_.box = effort.box;
  options_.bits_per_gene = std::clamp(options_.bits_per_gene, 2, 20);
  options_.tournament_size = std::max(1, options_.tournament_size);
}

const std::vector<Eigen::Vector2d>& GeneticAligner::fitnessSubset(
    const std::vector<Eigen::Vector2d>& all_points) {
  const std::size_t limit =
      options_.max_points > 0 ? static_cast<std::size_t>(options_.max_points) : all_points.size();
  if (all_points.size() <= limit) return all_points;
  subset_.clear();
  for (std::size_t i = 0; i < limit; ++i) subset_.push_back(all_points[i * all_points.size() / limit]);
  return subset_;
}

PreAlignResult GeneticAligner::align(const LookupTable& table, const std::vector<Eigen::Vector2d>& all_points,
                                     const Pose2D& guess, std::vector<Pose2D>* population_out,
                                     const LookupTable* coarse_table, const SearchEffort* effort_override) {
  FitnessPoints& points = prepared_;
  points.assign(fitnessSubset(all_points));
  FitnessStages stages;
  stages.fine = [&table, &points](const Pose2D& pose) { return table.fitness(points, pose); };
  if (coarse_table && !coarse_table->empty()) {
    stages.coarse = [coarse_table, &points](const Pose2D& pose) {
      return coarse_table->fitness(points, pose);
    };
  }
  stages.polish_step = table.options().cell_size;
  stages.max_fitness = static_cast<double>(table.maxCellValue()) * static_cast<double>(points.size());
  return align(stages, guess, population_out, effort_override);
}

PreAlignResult GeneticAligner::align(const FitnessStages& stages, const Pose2D& guess,
                                     std::vector<Pose2D>* population_out,
                                     const SearchEffort* effort_override) {
  const SearchEffort effort = effort_override ? sanitised(*effort_override) : effortOf(options_);
  PreAlignResult result;
  result.pose = guess;
  // The guess itself competes: the GA never returns something worse than the prediction.
  result.fitness = stages.fine(guess);
  result.evaluations = 1;

  const Codec codec(effort.box, guess, options_.bits_per_gene);
  Evolution evolution(options_, stages, codec, effort, rng_, &result.evaluations, &scratch_);
  std::vector<Individual>& best_run_population = scratch_.best_run;
  std::uint32_t best_run_fitness = 0;
  for (int run = 0; run < effort.runs; ++run) {
    const std::vector<Individual>& population = evolution.run();
    const auto best =
        std::max_element(population.begin(), population.end(),
                         [](const Individual& a, const Individual& b) { return a.fitness < b.fitness; });
    if (best->fitness > result.fitness) {
      result.fitness = best->fitness;
      result.pose = codec.decode(best->chromosome);
    }
    if (population_out && (run == 0 || best->fitness > best_run_fitness)) {
      best_run_fitness = best->fitness;
      best_run_population = population;
    }
  }

  polish(stages.fine, stages.polish_step, guess, effort.box, &result);

  if (population_out) {
    population_out->clear();
    for (const auto& individual : best_run_population)
      population_out->push_back(codec.decode(individual.chromosome));
  }
  const double max_fitness = stages.max_fitness;
  result.fitness_ratio = max_fitness > 0.0 ? result.fitness / max_fitness : 0.0;
  return result;
}

void GeneticAligner::polish(const PoseFitness& fitness_of, double finest_step, const Pose2D& guess,
                            const SearchBox& box, PreAlignResult* result) const {
  // Candidates stay inside the search box around the guess, like every GA individual.
  const auto inside_box = [&](const Pose2D& pose) {
    return std::abs(pose.x - guess.x) <= box.half_x && std::abs(pose.y - guess.y) <= box.half_y &&
           std::abs(normalizeAngle(pose.theta - guess.theta)) <= box.half_theta;
  };
  // Compass search: try +-step on each axis, move to the first improvement, halve the steps when none.
  const double cell = finest_step;
  double step_xy = 4.0 * cell;
  double step_theta = 0.02;
  int budget = options_.polish_evaluations;
  while (budget > 0 && step_xy >= 0.5 * cell) {
    bool improved = false;
    const Pose2D centre = result->pose;
    const Pose2D moves[6] = {Pose2D(step_xy, 0, 0),  Pose2D(-step_xy, 0, 0),   Pose2D(0, step_xy, 0),
                             Pose2D(0, -step_xy, 0), Pose2D(0, 0, step_theta), Pose2D(0, 0, -step_theta)};
    for (const Pose2D& move : moves) {
      if (budget-- <= 0) break;
      const Pose2D candidate(centre.x + move.x, centre.y + move.y, centre.theta + move.theta);
      if (!inside_box(candidate)) continue;
      const std::uint32_t fitness = fitness_of(candidate);
      ++result->evaluations;
      if (fitness > result->fitness) {
        result->fitness = fitness;
        result->pose = candidate;
        improved = true;
        break;
      }
    }
    if (!improved) {
      step_xy *= 0.5;
      step_theta *= 0.5;
    }
  }
}

}  // namespace hglasm
