// The papers' Success-Ratio protocol on real scans, ROS-free.
//
// A trial picks a random scan; the reference is its odd beams, the new scan its even beams seen from a
// sensor displaced by a known initial position error (IPE) T: new points = T^-1 * even points. The
// matcher starts from the identity (the "odometry" knows nothing), so the truth is exactly T and the
// error of a result P is |P.xy - T.xy| and |P.theta - T.theta| (wrapped).
// Trials are drawn per case from (seed, case, trial index) only, so every algorithm and preset sees
// the same pairs, and a case gives the same trials whatever other cases run alongside it.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/evaluation/baseline_matcher.h"

namespace hglasm {

/// A fixed-magnitude IPE: a translation of `translation_m` in a uniformly random direction and a
/// rotation of `rotation_deg` with a random sign.
struct IpeCase {
  double rotation_deg = 0.0;
  double translation_m = 0.0;
};

/// The papers' sweep: rotation 0, 10, 20, 30, 40, 50, 60, 80, 100, 120, 140, 160, 180 degrees times
/// translation 0.14, 0.57, 1.13, 2.12 m (includes the headline case 20 deg + 0.57 m).
std::vector<IpeCase> paperCases();

/// Parses "paper", "none" (no fixed cases) or "ROT_DEG:TRANS_M,..." (e.g. "20:0.57,90:1.13").
/// Rotations must lie in [0, 180] degrees and translations be finite and >= 0.
bool parseCases(const std::string& text, std::vector<IpeCase>* cases, std::string* error);

/// Success: |dxy| < xy and |dtheta| < theta (strictly), and a usable matcher status.
struct SuccessThresholds {
  double refined_xy = 0.10;      ///< metres, algorithms ending with MbICP
  double refined_theta = 0.01;   ///< radians
  double prealign_xy = 0.30;     ///< metres, GA-only algorithms (glasm_g, glasm_binary)
  double prealign_theta = 0.10;  ///< radians
};

struct SuccessRatioOptions {
  std::vector<Algorithm> algorithms;
  std::vector<Preset> presets;
  std::vector<IpeCase> cases;  ///< fixed-magnitude cases (may be empty if in_box)
  bool in_box = false;         ///< add, per preset, trials with errors uniform in its whole box
  int trials = 100;            ///< per (algorithm, preset, case)
  std::uint64_t seed = 1;
  ScanConversionOptions conversion;
  int min_points_per_half = 40;  ///< scans whose odd or even half has fewer valid points are skipped
  SuccessThresholds thresholds;
  /// Pre-alignment vs fitness evaluations (the papers' Figures 5/6): GLASM-g and binary GLASM alone,
  /// per preset, at the preset's population and runs but with `curve_generations` generations, on
  /// errors uniform in the preset's box. 0 = do not run.
  int curve_trials = 0;
  /// Generation counts for the curves; empty = 1, 2, 3, 4, 6, 8, 10, 12, 16, 20, 24 up to twice the
  /// preset's own generation count.
  std::vector<int> curve_generations;
  /// The GA-alone algorithms of the curves (kGlasmG, kGlasmBinary, kPga).
  std::vector<Algorithm> curve_algorithms{Algorithm::kGlasmG, Algorithm::kGlasmBinary, Algorithm::kPga};
  /// Per (algorithm, preset): the success ratio at zero initial error (the halves matched from the
  /// identity), `trials` trials of the case 0:0, reported beside every row as its ceiling.
  bool ceiling = true;
  /// Per scan (empty, or one per input scan): the pose of the even half's sensor in the odd half's frame
  /// when the halves were not recorded at the same instant (interlaced sweeps, see halfScanOffset). The
  /// truth of a trial is then offset * IPE.
  std::vector<Pose2D> half_offsets;
};

/// Success-ratio levels of the time-to-reach table (the papers' Figure 6).
std::vector<double> timeToReachLevels();

/// One CSV row: one (algorithm, preset, case).
struct SuccessRatioRow {
  Algorithm algorithm = Algorithm::kHglasmG;
  Preset preset = Preset::kSmall;
  bool in_box = false;  ///< errors uniform in the preset's box; `ipe` is then unused
  IpeCase ipe;
  int trials = 0;
  int successes = 0;
  double success_ratio = 0.0;
  double mean_dxy_m = 0.0;  ///< over all trials, failures included
  double mean_dth_deg = 0.0;
  double mean_ms = 0.0;           ///< wall time of setReference() + match(): the table build is included
  int failed_status = 0;          ///< trials whose matcher status was a failure (never a success)
  double mean_evaluations = 0.0;  ///< GA fitness evaluations per match
  /// Success ratio of the same (algorithm, preset) at zero initial error (options.ceiling); -1 if not run.
  double ceiling = -1.0;
  int ceiling_successes = 0;
  int ceiling_trials = 0;
};

/// One point of the pre-alignment-vs-evaluations curves.
struct EvaluationCurvePoint {
  Algorithm algorithm = Algorithm::kGlasmG;  ///< kGlasmG, kGlasmBinary or kPga
  Preset preset = Preset::kSmall;
  int population = 0;
  int generations = 0;
  int runs = 0;
  int trials = 0;
  int successes = 0;  ///< pre-alignment criterion (prealign_xy / prealign_theta)
  double success_ratio = 0.0;
  double mean_evaluations = 0.0;
  double mean_dxy_m = 0.0;
  double mean_dth_deg = 0.0;
  double mean_ms = 0.0;  ///< table build included
  double median_dxy_m = 0.0;
  double median_dth_deg = 0.0;
  /// Time of the search alone: mean_ms less the reference's preparation (lookup tables, coarse table
  /// included; PGA: sorting the reference into angular steps), as the papers time it.
  double mean_search_ms = 0.0;
};

/// Figure 6: the time one GA-alone algorithm needs to reach a success ratio: the curve's point with the
/// fewest generations whose success ratio reaches the level (the curves are measured, not fitted).
struct TimeToReach {
  Algorithm algorithm = Algorithm::kGlasmG;
  Preset preset = Preset::kSmall;
  double level = 0.0;  ///< success ratio, 0..1
  bool reached = false;
  int generations = 0;
  double evaluations = 0.0;
  double success_ratio = 0.0;  ///< of that point (>= level)
  double search_ms = 0.0;      ///< preparation excluded (the papers' timing)
  double total_ms = 0.0;       ///< preparation included
};

/// One TimeToReach per (preset, algorithm, level) of the curves, in the curves' order.
std::vector<TimeToReach> timeToReach(const std::vector<EvaluationCurvePoint>& curve,
                                     const std::vector<double>& levels);

struct SuccessRatioReport {
  std::vector<SuccessRatioRow> rows;        ///< by algorithm, preset (option order), then case, box last
  std::vector<EvaluationCurvePoint> curve;  ///< by preset, algorithm, generations
  std::size_t scans_total = 0;
  std::size_t scans_used = 0;     ///< scans trials may pick
  std::size_t scans_skipped = 0;  ///< too few valid points (or unconvertible)
};

struct SuccessRatioProgress {
  std::size_t cells_done = 0;  ///< rows and curve points finished
  std::size_t cells_total = 0;
  std::string message;  ///< one line describing the cell just finished
};
using SuccessRatioProgressCallback = std::function<void(const SuccessRatioProgress&)>;

/// Runs the protocol on `scans` (single-threaded, deterministic for a seed except for the timings).
/// False (with *error) on invalid options or when no scan has enough valid points.
bool runSuccessRatio(const std::vector<RangeScan>& scans, const SuccessRatioOptions& options,
                     SuccessRatioReport* report, std::string* error,
                     const SuccessRatioProgressCallback& progress = {});

/// The initial position error of trial `trial` of a fixed case (deterministic; exposed for tests).
Pose2D caseTrialError(const IpeCase& ipe, std::uint64_t seed, int trial, std::size_t scan_count,
                      std::size_t* scan_index);
/// The error of in-box trial `trial` for `box` (deterministic; exposed for tests).
Pose2D boxTrialError(const SearchBox& box, std::uint64_t seed, int trial, std::size_t scan_count,
                     std::size_t* scan_index);

/// The pose of the even half's sensor in the odd half's frame for a scan whose odd beams are recorded
/// `seconds` after its even ones (interlaced sweeps), the base moving at `base_velocity` (vx, vy in m/s,
/// omega in rad/s, base frame) and the laser mounted at `base_to_laser`: the inverse of the laser's
/// motion over `seconds` (first order: a rotation of -omega * seconds and the matching translation).
Pose2D halfScanOffset(const Eigen::Vector3d& base_velocity, const Pose2D& base_to_laser, double seconds);

}  // namespace hglasm
