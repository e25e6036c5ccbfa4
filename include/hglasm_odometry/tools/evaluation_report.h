// What evaluate prints: its inputs, the run (counts, fusion, CPU per stage), the relations metric of the
// laser odometry beside the wheels' (base and laser frame, direct pairs, calibration, the worst relations)
// and one SUMMARY line for scripts.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "hglasm_odometry/evaluation/relations.h"
#include "hglasm_odometry/tools/evaluate_setup.h"
#include "hglasm_odometry/tools/evaluation_run.h"

namespace hglasm_odometry {

/// One of the short relations with the largest translational errors, beside the wheels' error on it.
struct WorstRelation {
  double t1 = 0.0, span = 0.0;
  hglasm::RelationError laser;
  bool has_wheel = false;
  hglasm::RelationError wheel;
};

/// The relations metric of a run.
struct RelationsReport {
  double short_span = 10.0;  ///< seconds: the "short" rows
  hglasm::RelationStats laser_all, wheel_all, laser_short, wheel_short;
  /// The laser is off the base origin: the same metrics for the trajectories moved to the laser.
  bool laser_frame = false;
  hglasm::RelationStats laser_frame_all, wheel_laser_frame_all, laser_frame_short, wheel_laser_frame_short;
  bool has_direct_pairs = false;
  hglasm::RelationStats direct_pairs;  ///< short relations, each scan pair matched on its own
  /// Short relations their own scans contradict (the direct pairs more than kContradiction from the
  /// reference's turn and within kAgreement of the wheels'), and the metric over the rest.
  int contradicted = 0;
  hglasm::RelationStats laser_short_uncontradicted, wheel_short_uncontradicted;
  hglasm::CalibrationStats calibration_uncontradicted;
  static constexpr double kContradiction = 3.0 * M_PI / 180.0;  ///< radians
  static constexpr double kAgreement = 1.0 * M_PI / 180.0;      ///< radians
  /// Each estimate's clock against the reference's over the short relations (turn rates from the wheels).
  bool has_timing = false;
  hglasm::TimingFit laser_timing, wheel_timing, direct_pairs_timing;
  hglasm::CalibrationStats calibration;
  std::vector<WorstRelation> worst;  ///< the five largest short errors, largest first
  double worst_leap_ratio = 0.0;     ///< largest laser / (3 x wheel + 0.10 m): above 1 is a leap
  WorstRelation worst_leap;          ///< the relation with that ratio
};

/// The metric of `run` (against `wheel_trajectory`, the baseline) over relations up to `short_span` s;
/// with `direct_pairs_options` also each relation's scans matched on their own with those options.
RelationsReport evaluateRun(const std::vector<hglasm::Relation>& relations, const EvaluationRun& run,
                            const std::vector<hglasm::StampedPose>& wheel_trajectory, const BagData& data,
                            double short_span, const hglasm::TrackerOptions* direct_pairs_options = nullptr);

/// The bag, laser mount, wheel-stamp shift and options lines.
void printInputs(std::FILE* out, const EvaluateArguments& args, const EvaluateInputs& inputs,
                 const std::string& preset, bool use_odometry);

/// The run's warnings (the first few) and counts, fusion figures and CPU per stage; `data_seconds` is
/// the bag's span.
void printRun(std::FILE* out, const EvaluationRun& run, double data_seconds, bool warnings);

/// The metric's rows; `has_wheel` adds the wheels' column.
void printRelationsReport(std::FILE* out, const std::string& relations_path,
                          const std::vector<hglasm::Relation>& relations, const RelationsReport& report,
                          const std::string& base_frame, bool has_wheel);

/// --blend-wheels: the metric of the laser odometry's steps blended with the wheels' at fixed weights
/// (translation, heading: 0, 0.25, 0.5, 0.75, 1 each), one row per pair of weights: whether any fixed
/// re-weighting of the two inputs' steps would serve the relations better than the fusion's own.
void printWheelBlends(std::FILE* out, const std::vector<hglasm::Relation>& relations,
                      const std::vector<hglasm::StampedPose>& laser,
                      const std::vector<hglasm::StampedPose>& wheel, double short_span);

/// The machine-readable line scripts/evaluate_all.sh reads.
void printSummary(std::FILE* out, const std::string& preset, const EvaluationRun& run,
                  const RelationsReport& report);

}  // namespace hglasm_odometry
