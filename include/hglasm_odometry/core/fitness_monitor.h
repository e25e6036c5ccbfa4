// How well a scan fits the local map: on the local map's fine graded lookup table (the GA's own), read as a
// fitness ratio or as a likelihood field; and how well accepted matches usually fit.
#pragma once

#include <cstddef>
#include <vector>

#include "hglasm_odometry/core/local_map.h"
#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"

namespace hglasm {

/// The lookup tables a local map keeps for `matcher`: the GA's fine and coarse table.
std::vector<LookupTableOptions> mapTables(const MatcherOptions& matcher);
constexpr std::size_t kFineTable = 0;  ///< indices of the GA's tables in mapTables()
constexpr std::size_t kCoarseTable = 1;
/// The table of `map` (its tables from mapTables()) that scans are judged on: the fine one.
const LookupTable& judgingTable(const LocalMap& map);

/// A scan's likelihood weight: `independent_points` of its `points` count (the scan's information counts
/// no more; <= 0: all of them), divided by how many times the scan overstates its evidence.
double likelihoodWeight(double independent_points, std::size_t points, double evidence_scale);

/// One scan judged at any pose (the local map's frame) on a judging table. Holds references: the scan and
/// the table must stay unchanged until the next reset.
class ScanJudge {
 public:
  /// Judges nothing (every figure 0) until reset.
  ScanJudge() = default;
  /// `weight`: of the scan's likelihood (likelihoodWeight); `outlier`: the likelihood field's outlier share.
  ScanJudge(const LookupTable& table, const Scan& scan, double weight, double outlier);
  /// Judges `scan` against `table` from now on (both must outlive the judging), in the memory of the last.
  void reset(const LookupTable& table, const Scan& scan, double weight, double outlier);

  /// The cells the points hit / (255 * points): 1 = every point on the map; 0 without a table or points.
  double fitnessRatio(const Pose2D& pose) const;
  /// log p(scan | pose), of the scan's independent points (the table read as a likelihood field).
  double logLikelihood(const Pose2D& pose) const;
  /// log p(free space | pose): what the likelihood field leaves out. A beam crosses free space up to its
  /// end: something in front of a mapped wall (people) is allowed, a beam through the wall costs what an
  /// outlier point does.
  double freeSpaceLogLikelihood(const Pose2D& pose) const;

 private:
  bool usable() const { return table_ && scan_ && !table_->empty() && !scan_->empty(); }

  const LookupTable* table_ = nullptr;
  const Scan* scan_ = nullptr;
  FitnessPoints points_;  // the scan's finite points, prepared once for every pose judged
  double weight_ = 0.0;
  double outlier_ = 0.0;
};

/// How well accepted matches usually fit the map: the mean and variance of their fitness ratios,
/// exponentially forgotten (the usual fit drifts with the scene). Not thread-safe per instance.
class FitnessMonitor {
 public:
  /// A fit more than `max_sigmas` standard deviations below the mean is unusual.
  explicit FitnessMonitor(double max_sigmas);

  /// The fitness ratio of an accepted match.
  void add(double fitness_ratio);
  /// Whether a fit is as good as usual (true while fewer than kMinHistory matches are known).
  bool usual(double fitness_ratio) const;
  void reset();

  int count() const { return count_; }
  double mean() const { return mean_; }
  double variance() const { return variance_; }

  static constexpr int kMinHistory = 5;      // matches before the usual fit is known
  static constexpr double kHalfLife = 50.0;  // matches

 private:
  double max_sigmas_;
  int count_ = 0;
  double mean_ = 0.0;
  double variance_ = 0.0;
};

}  // namespace hglasm
