#include "hglasm_odometry/core/fitness_monitor.h"

#include <algorithm>
#include <cmath>

namespace hglasm {

std::vector<LookupTableOptions> mapTables(const MatcherOptions& matcher) {
  return {matcher.table, matcher.coarse_table};
}

const LookupTable& judgingTable(const LocalMap& map) { return map.table(kFineTable); }

double likelihoodWeight(double independent_points, std::size_t points, double evidence_scale) {
  const double weight =
      independent_points > 0.0 ? std::min(1.0, independent_points / std::max<double>(1.0, points)) : 1.0;
  return weight / evidence_scale;
}

ScanJudge::ScanJudge(const LookupTable& table, const Scan& scan, double weight, double outlier) {
  reset(table, scan, weight, outlier);
}

void ScanJudge::reset(const LookupTable& table, const Scan& scan, double weight, double outlier) {
  table_ = &table;
  scan_ = &scan;
  weight_ = weight;
  outlier_ = outlier;
  points_.assign(scan.points);
}

double ScanJudge::fitnessRatio(const Pose2D& pose) const {
  if (!usable()) return 0.0;
  const double best = static_cast<double>(table_->maxCellValue()) * static_cast<double>(scan_->size());
  return table_->fitness(points_, pose) / best;
}

double ScanJudge::logLikelihood(const Pose2D& pose) const {
  if (!usable()) return 0.0;
  return weight_ * table_->logLikelihood(points_, pose, outlier_);
}

double ScanJudge::freeSpaceLogLikelihood(const Pose2D& pose) const {
  if (!usable() || outlier_ <= 0.0) return 0.0;
  const int through = table_->beamsThroughSurfaces(scan_->points, pose, 3.0 * table_->options().sigma);
  return weight_ * through * std::log(outlier_);
}

FitnessMonitor::FitnessMonitor(double max_sigmas) : max_sigmas_(max_sigmas) {}

void FitnessMonitor::add(double fitness_ratio) {
  const double alpha = count_ == 0 ? 1.0 : std::max(1.0 / (count_ + 1), 1.0 - std::exp2(-1.0 / kHalfLife));
  const double delta = fitness_ratio - mean_;
  mean_ += alpha * delta;
  variance_ = (1.0 - alpha) * (variance_ + alpha * delta * delta);
  ++count_;
}

bool FitnessMonitor::usual(double fitness_ratio) const {
  return count_ < kMinHistory || fitness_ratio >= mean_ - max_sigmas_ * std::sqrt(variance_);
}

void FitnessMonitor::reset() {
  count_ = 0;
  mean_ = variance_ = 0.0;
}

}  // namespace hglasm
