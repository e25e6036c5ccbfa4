#include "hglasm_odometry/evaluation/baseline_matcher.h"

#include <cmath>

#include "hglasm_odometry/core/timing.h"

namespace hglasm {
namespace {

TableKernelFunction kernelOf(Algorithm algorithm) {
  return usesBinaryTables(algorithm) ? binaryKernel : gradedKernel;
}

}  // namespace

const char* toString(Algorithm algorithm) {
  switch (algorithm) {
    case Algorithm::kHglasmG:
      return "hglasm_g";
    case Algorithm::kHglasmBinary:
      return "hglasm_binary";
    case Algorithm::kGlasmG:
      return "glasm_g";
    case Algorithm::kGlasmBinary:
      return "glasm_binary";
    case Algorithm::kMbicp:
      return "mbicp";
    case Algorithm::kPga:
      return "pga";
    case Algorithm::kHpga:
      return "hpga";
  }
  return "unknown";
}

bool parseAlgorithm(const std::string& name, Algorithm* algorithm) {
  for (Algorithm candidate :
       {Algorithm::kHglasmG, Algorithm::kHglasmBinary, Algorithm::kGlasmG, Algorithm::kGlasmBinary,
        Algorithm::kMbicp, Algorithm::kPga, Algorithm::kHpga}) {
    if (name == toString(candidate)) {
      *algorithm = candidate;
      return true;
    }
  }
  return false;
}

bool usesGeneticStage(Algorithm algorithm) { return algorithm != Algorithm::kMbicp; }
bool usesMbicpStage(Algorithm algorithm) {
  return algorithm == Algorithm::kHglasmG || algorithm == Algorithm::kHglasmBinary ||
         algorithm == Algorithm::kMbicp || algorithm == Algorithm::kHpga;
}
bool usesPolarPairing(Algorithm algorithm) {
  return algorithm == Algorithm::kPga || algorithm == Algorithm::kHpga;
}
bool usesBinaryTables(Algorithm algorithm) {
  return algorithm == Algorithm::kHglasmBinary || algorithm == Algorithm::kGlasmBinary;
}

TableKernel binaryKernel(const LookupTableOptions& options) {
  TableKernel kernel;
  kernel.radius = static_cast<int>(std::ceil(options.sigma * (1.0 / options.cell_size) - 1e-9));
  const auto side = static_cast<std::size_t>(2 * kernel.radius + 1);
  kernel.values.assign(side * side, 1);
  return kernel;
}

BaselineOptions baselineOptions(Algorithm algorithm, Preset preset) {
  BaselineOptions options;
  options.algorithm = algorithm;
  options.matcher = presetOptions(preset);
  return options;
}

PolarPairingOptions polarPairingOptions(const MatcherOptions& matcher) {
  PolarPairingOptions options;
  options.pairing_threshold = matcher.table.cutoff;
  options.coarse_pairing_threshold = matcher.coarse_table.cutoff;
  return options;
}

BaselineMatcher::BaselineMatcher(const BaselineOptions& options)
    : options_(options),
      table_(options.matcher.table, kernelOf(options.algorithm)),
      coarse_table_(options.matcher.coarse_table, kernelOf(options.algorithm)),
      aligner_(options.matcher.genetic),
      mbicp_(options.matcher.mbicp),
      polar_pairing_(polarPairingOptions(options.matcher)) {}

void BaselineMatcher::setReference(const Scan& scan) {
  ReferencePoints reference;
  reference.append(scan.points);
  const auto start = std::chrono::steady_clock::now();
  if (usesPolarPairing(options_.algorithm)) {
    polar_pairing_.build(reference);  // PGA's preparation: sorting the reference by angle
  } else if (usesGeneticStage(options_.algorithm)) {
    table_.build(reference);
    reference_ = reference;
    coarse_table_stale_ = true;
  }
  table_build_ms_ = millisecondsSince(start);
  // Built for every algorithm, as the papers' timings (and the figures measured so far) count it.
  mbicp_.setReference(reference);
  has_reference_ = !reference.empty();
}

void BaselineMatcher::prealign(const Scan& scan, std::vector<Pose2D>* population_out, MatchResult* result) {
  const auto start = std::chrono::steady_clock::now();
  PreAlignResult prealigned;
  if (usesPolarPairing(options_.algorithm)) {
    pga_points_.assign(aligner_.fitnessSubset(scan.points));
    const FitnessStages stages =
        polarPairingStages(polar_pairing_, pga_points_, options_.matcher.table.cell_size);
    prealigned = aligner_.align(stages, result->pose, population_out);
  } else {
    if (options_.matcher.genetic.coarse_generations > 0 && coarse_table_stale_) {
      coarse_table_.build(reference_);
      coarse_table_stale_ = false;
      coarse_table_build_ms_ = millisecondsSince(start);
    }
    prealigned = aligner_.align(table_, scan.points, result->pose, population_out, &coarse_table_);
  }
  result->prealign_ms = millisecondsSince(start);
  applyPrealignment(prealigned, result);
}

MatchResult BaselineMatcher::match(const Scan& scan, const Pose2D& guess,
                                   std::vector<Pose2D>* population_out) {
  MatchResult result;
  if (!startMatch(has_reference_, scan, guess, &result)) return result;
  coarse_table_build_ms_ = 0.0;
  if (usesGeneticStage(options_.algorithm)) {
    prealign(scan, population_out, &result);
    if (!usesMbicpStage(options_.algorithm)) {
      result.status = result.prealigned_fitness > 0 ? MatchStatus::kOk : MatchStatus::kLowFitness;
      // The GA's own precision: about one sigma of the lookup kernel in translation.
      const double sigma = options_.matcher.table.sigma;
      result.covariance = Eigen::Vector3d(sigma * sigma, sigma * sigma, 0.02 * 0.02).asDiagonal();
      return result;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const MbicpResult refined = mbicp_.match(scan, result.prealigned_pose);
  result.refine_ms = millisecondsSince(start);
  applyRefinement(refined, &result);
  return result;
}

}  // namespace hglasm
