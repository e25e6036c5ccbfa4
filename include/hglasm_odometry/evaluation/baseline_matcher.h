// The papers' algorithms side by side (the success_ratio tool): HGLASM-g, the odometry's matcher, and its
// baselines (binary GLASM, either GA alone, MbICP alone, PGA and the hybrid HPGA), each composed of the
// core's pieces (GeneticAligner, LookupTable, Mbicp) and PGA's polar pairing. Only the tools and tests link
// it: the odometry runs core's ScanMatcher.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hglasm_odometry/core/genetic_aligner.h"
#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/mbicp.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/evaluation/polar_pairing.h"

namespace hglasm {

/// The matcher family of the papers.
enum class Algorithm {
  kHglasmG,       ///< graded-table GA, then MbICP (the method: what ScanMatcher runs)
  kHglasmBinary,  ///< binary-table GA, then MbICP
  kGlasmG,        ///< graded-table GA alone
  kGlasmBinary,   ///< binary-table GA alone
  kMbicp,         ///< MbICP alone from the guess
  kPga,           ///< PGA (Martinez et al. 2006): the same GA on polar pairing, no lookup table, alone
  kHpga,          ///< PGA, then MbICP (the hybrid GA-ICP, with this matcher's MbICP)
};
const char* toString(Algorithm algorithm);
/// Parses "hglasm_g", "hglasm_binary", "glasm_g", "glasm_binary", "mbicp", "pga", "hpga". False if unknown.
bool parseAlgorithm(const std::string& name, Algorithm* algorithm);
bool usesGeneticStage(Algorithm algorithm);
bool usesMbicpStage(Algorithm algorithm);
/// PGA and HPGA: the GA scores poses by polar pairing instead of a lookup table.
bool usesPolarPairing(Algorithm algorithm);
/// hglasm_binary and glasm_binary: the GA's tables are binary.
bool usesBinaryTables(Algorithm algorithm);

/// GLASM's (binary) stamp: 1 in a square of half-side `sigma` around the reference point.
TableKernel binaryKernel(const LookupTableOptions& options);

struct BaselineOptions {
  Algorithm algorithm = Algorithm::kHglasmG;
  MatcherOptions matcher;  ///< the tables (binary for the binary algorithms), the GA, MbICP
};
/// A preset's options for `algorithm`.
BaselineOptions baselineOptions(Algorithm algorithm, Preset preset);
/// PGA's (and HPGA's) pairing: within the reach of GLASM's tables (the fine table's cut-off, then the coarse
/// one's). Derived when the matcher is built, so an override of a table's cut-off reaches it.
PolarPairingOptions polarPairingOptions(const MatcherOptions& matcher);

/// One algorithm on one reference at a time (setReference() prepares what it needs: lookup tables, the
/// coarse one on first use, PGA's angular sort, MbICP's structure). Not thread-safe per instance.
class BaselineMatcher {
 public:
  explicit BaselineMatcher(const BaselineOptions& options);

  void setReference(const Scan& reference);
  /// Matches `scan` against the reference from `guess`, as the algorithm does. The GA alone reports kOk
  /// when its pose scores at all (kLowFitness otherwise) and a covariance of about its precision.
  MatchResult match(const Scan& scan, const Pose2D& guess, std::vector<Pose2D>* population_out = nullptr);

  bool hasReference() const { return has_reference_; }
  /// Time the last setReference() spent preparing the GA's fitness (tables or angular sort).
  double lastTableBuildMs() const { return table_build_ms_; }
  /// Time the last match() spent building the coarse table (built on first use; 0 if it did not).
  double lastCoarseTableBuildMs() const { return coarse_table_build_ms_; }
  /// The GA's fine lookup table (empty for MbICP, PGA and HPGA).
  const LookupTable& table() const { return table_; }
  /// PGA's angular sort (empty for the other algorithms).
  const PolarPairing& polarPairing() const { return polar_pairing_; }
  Algorithm algorithm() const { return options_.algorithm; }
  const BaselineOptions& options() const { return options_; }
  void reseed(std::uint64_t seed) { aligner_.reseed(seed); }

 private:
  /// The GA stage into `result`.
  void prealign(const Scan& scan, std::vector<Pose2D>* population_out, MatchResult* result);

  BaselineOptions options_;
  LookupTable table_;
  LookupTable coarse_table_;
  GeneticAligner aligner_;
  Mbicp mbicp_;
  PolarPairing polar_pairing_;  // PGA's "table": the reference sorted into angular steps
  FitnessPoints pga_points_;    // scratch: the new scan's points for PGA's fitness
  ReferencePoints reference_;   // for the coarse table, built on first use
  bool coarse_table_stale_ = false;
  bool has_reference_ = false;
  double table_build_ms_ = 0.0;
  double coarse_table_build_ms_ = 0.0;
};

}  // namespace hglasm
