// HGLASM-g: genetic pre-alignment on a graded lookup table, refined by MbICP, composed in SE(2).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "hglasm_odometry/core/genetic_aligner.h"
#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/mbicp.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

/// Search-space presets of the papers' Table 1.
enum class Preset { kSmall, kMedium, kLarge };
const char* toString(Preset preset);
bool parsePreset(const std::string& name, Preset* preset);

/// The coarse table's defaults: a wider basin than the fine table's.
inline LookupTableOptions coarseTableOptions() {
  LookupTableOptions options;
  options.cell_size = 0.08;
  options.sigma = 0.30;
  options.cutoff = 0.60;
  return options;
}

/// The defaults are the medium preset (the default ~preset), as config/presets.yaml documents it.
struct MatcherOptions {
  LookupTableOptions table;
  /// Table for the GA's first genetic.coarse_generations generations.
  LookupTableOptions coarse_table = coarseTableOptions();
  GeneticOptions genetic;
  /// Measured (README): the information of at most 100 independent points (intel, fr079, aces: with 50 the
  /// fused odometry leans on the wheels where the scans know better, with 200 it takes the scans'
  /// look-alike leaps). MbicpOptions' robust weights, surfaces and point noise: see its fields.
  MbicpOptions mbicp = [] {
    MbicpOptions measured;
    measured.independent_points = 100.0;
    return measured;
  }();
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, MatcherOptions* options) {
  visitOptions(visitor, "table/", &options->table);
  visitOptions(visitor, "coarse_table/", &options->coarse_table);
  visitOptions(visitor, &options->genetic);
  visitOptions(visitor, &options->mbicp);
}

/// Each preset: the defaults above with the search space of the papers' Table 1 (config/presets.yaml lists
/// what each changes, for ROS users).
MatcherOptions presetOptions(Preset preset);

enum class MatchStatus {
  kOk,
  kNoReference,        ///< match() before setReference(), or an empty reference
  kTooFewPoints,       ///< the new scan has too few valid points
  kLowFitness,         ///< (pre-alignment alone, the evaluation's baselines) nothing in the box fits
  kMbicpFailed,        ///< MbICP: too few associations or degenerate geometry
  kMbicpNotConverged,  ///< MbICP hit its iteration limit (result usable, flagged)
};
const char* toString(MatchStatus status);

struct MatchResult {
  Pose2D pose;             ///< new scan in the reference frame (final)
  Pose2D prealigned_pose;  ///< after the GA (the guess when there is no GA stage)
  MatchStatus status = MatchStatus::kNoReference;
  /// The GA's own fitness of prealigned_pose (its lookup table's cells; 0 without a GA stage). How well the
  /// final pose fits is the caller's to judge (OdometryTracker: on the fine table).
  std::uint32_t prealigned_fitness = 0;
  double prealigned_fitness_ratio =
      0.0;              ///< prealigned_fitness / its value with every point on the reference
  int evaluations = 0;  ///< GA fitness evaluations
  int iterations = 0;   ///< MbICP iterations
  int associations = 0;
  double rms_error = 0.0;  ///< MbICP residual, metres
  MbicpStatus mbicp_status = MbicpStatus::kConverged;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  ///< of (x, y, theta); see Mbicp
  /// Calibrated information of the scan alone at `pose` (zero without an MbICP stage); see Mbicp.
  Eigen::Matrix3d scan_information = Eigen::Matrix3d::Zero();
  InformationDirections scan_directions;  ///< its directions before the noise scale (see Mbicp)
  bool degenerate = false;                ///< the scan alone leaves a direction unconstrained (see Mbicp)
  Pose2D scan_only_pose;                  ///< where the scan alone puts the pose (see Mbicp)
  double prealign_ms = 0.0;
  double refine_ms = 0.0;

  bool ok() const { return status == MatchStatus::kOk; }
};

/// The stages of a match, for matchers composed of them (ScanMatcher; the evaluation's baselines).
/// Starts `result` at `guess` (the identity if not finite) with a large covariance; false, with the status
/// saying why, when there is nothing to match (no reference, fewer than 3 points).
bool startMatch(bool has_reference, const Scan& scan, const Pose2D& guess, MatchResult* result);
/// The GA's pose, fitness and evaluations into `result` (its pose too).
void applyPrealignment(const PreAlignResult& prealigned, MatchResult* result);
/// MbICP's pose, covariance, information and status into `result` (not its time).
void applyRefinement(const MbicpResult& refined, MatchResult* result);

/// HGLASM-g, the odometry's matcher: the GA on the graded lookup tables, then MbICP. One reference at a
/// time; its lookup table and MbICP structure are built once in setReference().
class ScanMatcher {
 public:
  explicit ScanMatcher(const MatcherOptions& options = {});

  /// Builds the lookup table (unless the caller keeps the tables, useTables) and the MbICP reference.
  void setReference(const Scan& reference);
  /// The same from several scans in one frame (a local map).
  void setReference(const ReferencePoints& reference);
  /// The same after scans were appended to that reference (Mbicp::extendReference): its scans before
  /// `first_new_scan` are unchanged. With tables kept by the caller (useTables) only MbICP's structure grows.
  void extendReference(const ReferencePoints& reference, std::size_t first_new_scan);
  bool hasReference() const { return has_reference_; }
  double lastTableBuildMs() const { return table_build_ms_; }
  /// Time the last match() spent building the coarse table (built on first use; 0 if it did not).
  double lastCoarseTableBuildMs() const { return coarse_table_build_ms_; }

  /// Matches `scan` (points in its own frame) against the reference, starting from `guess`. `effort`
  /// (optional) replaces the preset's box and GA size; `prior` (optional) makes MbICP's result the
  /// maximum a posteriori pose of scan and prior.
  MatchResult match(const Scan& scan, const Pose2D& guess, std::vector<Pose2D>* population_out = nullptr,
                    const SearchEffort* effort = nullptr, const PosePrior* prior = nullptr);

  /// MbICP alone from `guess` (no pre-alignment), e.g. to check a match that strayed far from a prediction.
  MatchResult refine(const Scan& scan, const Pose2D& guess, const PosePrior* prior = nullptr);

  /// Fitness ratio of `scan` at `pose` on the fine lookup table (0 without a table).
  double fitnessRatioAt(const Scan& scan, const Pose2D& pose) const;

  /// Log-likelihood of `scan` at `pose` on the fine lookup table read as a likelihood field (see
  /// LookupTable::logLikelihood), summed over the scan's points; 0 without a table.
  double logLikelihoodAt(const Scan& scan, const Pose2D& pose, double outlier) const;

  const MatcherOptions& options() const { return options_; }
  const LookupTable& table() const { return fineTable(); }
  /// Lookup tables kept by the caller (a local map's, grown keyframe by keyframe, answering in the frame of
  /// the reference given to setReference()), which then builds only MbICP's structure. nullptr:
  /// the matcher's own, built by setReference().
  void useTables(const LookupTable* fine, const LookupTable* coarse) {
    external_fine_ = fine;
    external_coarse_ = coarse;
  }
  /// How far the scan's information is to be believed, direction by direction (Mbicp::setScanNoiseScale).
  void setScanNoiseScale(const ScanNoiseScale& scale) { mbicp_.setScanNoiseScale(scale); }
  void reseed(std::uint64_t seed) { aligner_.reseed(seed); }

 private:
  MatcherOptions options_;
  LookupTable table_;
  LookupTable coarse_table_;
  const LookupTable* external_fine_ = nullptr;
  const LookupTable* external_coarse_ = nullptr;
  const LookupTable& fineTable() const { return external_fine_ ? *external_fine_ : table_; }
  const LookupTable& coarseTable() const { return external_coarse_ ? *external_coarse_ : coarse_table_; }
  GeneticAligner aligner_;
  Mbicp mbicp_;
  void refineInto(const Scan& scan, const PosePrior* prior, MatchResult* result);

  bool has_reference_ = false;
  double table_build_ms_ = 0.0;
  double coarse_table_build_ms_ = 0.0;
  // The coarse table is built on first use: searches sized by a tight prior never need it.
  ReferencePoints reference_;
  bool coarse_table_stale_ = false;
};

}  // namespace hglasm
