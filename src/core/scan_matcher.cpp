#include "hglasm_odometry/core/scan_matcher.h"

#include <chrono>
#include <cmath>

namespace hglasm {
namespace {

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

TableKind tableKindOf(Algorithm algorithm) {
  return algorithm == Algorithm::kHglasmBinary || algorithm == Algorithm::kGlasmBinary ? TableKind::kBinary
                                                                                       : TableKind::kGraded;
}

LookupTableOptions tableOptionsFor(const LookupTableOptions& base, Algorithm algorithm) {
  LookupTableOptions table = base;
  table.kind = tableKindOf(algorithm);
  return table;
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

const char* toString(Preset preset) {
  switch (preset) {
    case Preset::kSmall:
      return "small";
    case Preset::kMedium:
      return "medium";
    case Preset::kLarge:
      return "large";
  }
  return "unknown";
}

bool parsePreset(const std::string& name, Preset* preset) {
  for (Preset candidate : {Preset::kSmall, Preset::kMedium, Preset::kLarge}) {
    if (name == toString(candidate)) {
      *preset = candidate;
      return true;
    }
  }
  return false;
}

MatcherOptions presetOptions(Preset preset) {
  // The defaults of MatcherOptions are the medium preset; the papers' Table 1 grows box and GA together.
  MatcherOptions options;
  switch (preset) {
    case Preset::kSmall:
      options.genetic.box = {0.3, 0.3, 0.3};
      options.genetic.population = 20;
      options.genetic.generations = 6;
      options.genetic.coarse_generations = 0;
      break;
    case Preset::kMedium:
      break;
    case Preset::kLarge:
      options.genetic.box = {2.0, 2.0, M_PI};
      options.genetic.population = 200;
      options.genetic.generations = 12;
      options.genetic.runs = 2;
      // The +-pi box: a wider, coarser first stage (sigma 0.6 m on 12 cm cells) for half the generations
      // finds the true basin instead of a 180-degree look-alike more often (intel, whole box, 5 seeds of
      // 500 trials: 97.1 -> 98.6 %).
      options.genetic.coarse_generations = 6;
      options.coarse_table.cell_size = 0.12;
      options.coarse_table.sigma = 0.60;
      options.coarse_table.cutoff = 1.20;
      break;
  }
  // PGA pairs within the reach of GLASM's tables: the fine table's cut-off, then the coarse one's.
  options.pga.pairing_threshold = options.table.cutoff;
  options.pga.coarse_pairing_threshold = options.coarse_table.cutoff;
  return options;
}

const char* toString(MatchStatus status) {
  switch (status) {
    case MatchStatus::kOk:
      return "ok";
    case MatchStatus::kNoReference:
      return "no_reference";
    case MatchStatus::kTooFewPoints:
      return "too_few_points";
    case MatchStatus::kLowFitness:
      return "low_fitness";
    case MatchStatus::kMbicpFailed:
      return "mbicp_failed";
    case MatchStatus::kMbicpNotConverged:
      return "mbicp_not_converged";
  }
  return "unknown";
}

ScanMatcher::ScanMatcher(const MatcherOptions& options)
    : options_(options),
      table_(tableOptionsFor(options.table, options.algorithm)),
      coarse_table_(tableOptionsFor(options.coarse_table, options.algorithm)),
      aligner_(options.genetic),
      mbicp_(options.mbicp),
      polar_pairing_(options.pga) {}

void ScanMatcher::setReference(const Scan& reference) {
  ReferencePoints single;
  single.append(reference.points);
  setReference(single);
}

void ScanMatcher::setReference(const ReferencePoints& reference) {
  const auto start = std::chrono::steady_clock::now();
  if (usesPolarPairing(options_.algorithm)) {
    polar_pairing_.build(reference);  // PGA's preparation: sorting the reference by angle
  } else if (usesGeneticStage(options_.algorithm) && !external_fine_) {
    table_.build(reference);
    reference_ = reference;
    coarse_table_stale_ = true;
  }
  table_build_ms_ = millisecondsSince(start);
  mbicp_.setReference(reference);
  has_reference_ = !reference.empty();
}

void ScanMatcher::extendReference(const ReferencePoints& reference, std::size_t first_new_scan) {
  if (first_new_scan == 0 || !external_fine_ || usesPolarPairing(options_.algorithm)) {
    setReference(reference);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  mbicp_.extendReference(reference, first_new_scan);
  table_build_ms_ = millisecondsSince(start);
  has_reference_ = !reference.empty();
}

bool ScanMatcher::startResult(const Scan& scan, const Pose2D& guess, MatchResult* result) const {
  result->pose = result->prealigned_pose = guess.isFinite() ? guess : Pose2D();
  // Without a trustworthy estimate the covariance says so (finite, large).
  result->covariance = Eigen::Matrix3d::Identity() * 1e4;
  if (!has_reference_) {
    result->status = MatchStatus::kNoReference;
    return false;
  }
  if (scan.size() < 3) {
    result->status = MatchStatus::kTooFewPoints;
    return false;
  }
  return true;
}

MatchResult ScanMatcher::match(const Scan& scan, const Pose2D& guess, std::vector<Pose2D>* population_out,
                               const SearchEffort* effort, const PosePrior* prior) {
  MatchResult result;
  if (!startResult(scan, guess, &result)) return result;
  const Pose2D start_pose = result.pose;

  coarse_table_build_ms_ = 0.0;
  if (usesGeneticStage(options_.algorithm)) {
    const auto start = std::chrono::steady_clock::now();
    const int coarse_generations = effort ? effort->coarse_generations : options_.genetic.coarse_generations;
    const bool polar = usesPolarPairing(options_.algorithm);
    if (!polar && !external_coarse_ && coarse_generations > 0 && coarse_table_stale_) {
      coarse_table_.build(reference_);
      coarse_table_stale_ = false;
      coarse_table_build_ms_ = millisecondsSince(start);
    }
    PreAlignResult prealigned;
    if (polar) {
      pga_points_.assign(aligner_.fitnessSubset(scan.points));
      const FitnessStages stages = polarPairingStages(polar_pairing_, pga_points_, options_.table.cell_size);
      prealigned = aligner_.align(stages, start_pose, population_out, effort);
    } else {
      prealigned =
          aligner_.align(fineTable(), scan.points, start_pose, population_out, &coarseTable(), effort);
    }
    result.prealign_ms = millisecondsSince(start);
    result.prealigned_pose = result.pose = prealigned.pose;
    result.prealigned_fitness = prealigned.fitness;
    result.prealigned_fitness_ratio = prealigned.fitness_ratio;
    result.evaluations = prealigned.evaluations;
    if (!usesMbicpStage(options_.algorithm)) {
      result.status = prealigned.fitness > 0 ? MatchStatus::kOk : MatchStatus::kLowFitness;
      // The GA's own precision: about one sigma of the lookup kernel in translation.
      const double sigma = options_.table.sigma;
      result.covariance = Eigen::Vector3d(sigma * sigma, sigma * sigma, 0.02 * 0.02).asDiagonal();
      return result;
    }
  }

  refineInto(scan, prior, &result);
  return result;
}

void ScanMatcher::refineInto(const Scan& scan, const PosePrior* prior, MatchResult* result) {
  const auto start = std::chrono::steady_clock::now();
  const MbicpResult refined = mbicp_.match(scan, result->prealigned_pose, prior);
  result->refine_ms = millisecondsSince(start);
  result->pose = refined.pose;
  result->iterations = refined.iterations;
  result->associations = refined.associations;
  result->rms_error = refined.rms_error;
  result->mbicp_status = refined.status;
  result->covariance = refined.covariance;
  result->scan_information = refined.scan_information;
  result->scan_directions = refined.scan_directions;
  result->degenerate = refined.degenerate;
  result->scan_only_pose = refined.scan_only_pose;
  switch (refined.status) {
    case MbicpStatus::kConverged:
      result->status = MatchStatus::kOk;
      break;
    case MbicpStatus::kMaxIterations:
      result->status = MatchStatus::kMbicpNotConverged;
      break;
    case MbicpStatus::kTooFewAssociations:
    case MbicpStatus::kDegenerate:
      result->status = MatchStatus::kMbicpFailed;
      break;
  }
}

MatchResult ScanMatcher::refine(const Scan& scan, const Pose2D& guess, const PosePrior* prior) {
  MatchResult result;
  if (!startResult(scan, guess, &result)) return result;
  refineInto(scan, prior, &result);
  return result;
}

double ScanMatcher::fitnessRatioAt(const Scan& scan, const Pose2D& pose) const {
  const LookupTable& table = fineTable();
  if (table.empty() || scan.empty()) return 0.0;
  const double best = static_cast<double>(table.maxCellValue()) * static_cast<double>(scan.size());
  return table.fitness(scan.points, pose) / best;
}

double ScanMatcher::logLikelihoodAt(const Scan& scan, const Pose2D& pose, double outlier) const {
  if (fineTable().empty() || scan.empty()) return 0.0;
  FitnessPoints points;
  points.assign(scan.points);
  return fineTable().logLikelihood(points, pose, outlier);
}

}  // namespace hglasm
