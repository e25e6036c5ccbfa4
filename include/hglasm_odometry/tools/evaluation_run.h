// One pass of the nodelet's pipeline over a bag as the nodelet receives it, what it produced, and the
// bag-level pieces of its evaluation: the wheel baseline, each relation's scans matched on their own, the
// map picture.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/evaluation/relations.h"
#include "hglasm_odometry/ros/parameters.h"
#include "hglasm_odometry/tools/bag_reader.h"
#include "hglasm_odometry/tools/bag_replay.h"

namespace hglasm_odometry {

/// What one pass of the pipeline over the bag produced.
struct EvaluationRun {
  std::vector<hglasm::StampedPose> trajectory;  ///< published base poses, by stamp
  /// What the relations score: the published poses and, at every scan the pipeline did not publish (dropped
  /// by the time policy or the queue), the pose interpolated between the published ones around it (what tf
  /// gives at that time), so that every relation is scored; `interpolated` of them.
  std::vector<hglasm::StampedPose> scored;
  std::size_t interpolated = 0;
  std::vector<hglasm::TrackerUpdate> updates;  ///< every published scan's update, in order
  std::size_t processed = 0, skipped = 0, stale = 0;
  int matched = 0, fallbacks = 0, keyframes = 0, resets = 0, conversion_errors = 0, warnings = 0;
  int deskewed = 0, reanchored = 0;
  std::vector<std::pair<double, std::string>> first_warnings;  ///< stamp and text, the first few
  ReplayCounts replay;
  hglasm::InputCounts inputs;
  double time_offset = 0.0;  ///< the wheels' time offset in use at the end
  std::string beam_times;    ///< where the first scan's beam times came from
  std::map<std::string, int> statuses, predictions;
  std::vector<double> total_ms, convert_ms, prealign_ms, refine_ms, table_ms;
};

/// Runs the pipeline with `tracker` options over `data` as the nodelet with `nodelet` options receives
/// it (replayBag: the bag's order, the nodelet's waits and queue), the scans first thinned to one per
/// `min_scan_interval` seconds (a throttled topic; 0: all). `pace_rate` > 0 processes each scan no earlier
/// than a live node playing the bag at that rate would receive it (ReplayOptions::pace_rate). Keeps the
/// first `warnings_kept` warnings.
EvaluationRun runEvaluation(const BagData& data, const LaserOdometryOptions& nodelet,
                            const hglasm::TrackerOptions& tracker, double min_scan_interval,
                            double pace_rate = 0.0, std::size_t warnings_kept = 20);

/// run->scored and run->interpolated from run->trajectory at the stamps of `data`'s scans (both sorted by
/// stamp); scans before the first published pose or after the last stay unscored.
void scoreAtEveryScan(const BagData& data, EvaluationRun* run);

/// The arrivals of `data` but for the scans stamped less than `interval` s after the last one kept.
std::vector<BagArrival> thinnedArrivals(const BagData& data, double interval, std::size_t* skipped);

/// The increment covariance of every published scan (writeTrajectory, evaluateCalibration).
std::vector<Eigen::Matrix3d> incrementCovariances(const EvaluationRun& run);

/// The scan conversion the pipeline with `options` uses for this bag (mirrored for an upside-down laser).
hglasm::ScanConversionOptions pipelineConversion(const hglasm::TrackerOptions& options, const BagData& data);

/// The bag's wheel odometry at its scan stamps, read `shift` s later (wheels moved later by as much):
/// the baseline the laser odometry must beat.
std::vector<hglasm::StampedPose> wheelTrajectory(const BagData& data, double shift = 0.0);

/// Each relation's scan pair matched on its own with MbICP started from the reference motion: base-frame
/// motions, valid where both stamps have a scan and MbICP converged (relations over `max_span` s left
/// out). Not odometry: it shows how far the matcher's optimum of those very scans lies from the reference.
void directPairMotions(const hglasm::TrackerOptions& options, const BagData& data,
                       const std::vector<hglasm::Relation>& relations, double max_span,
                       std::vector<hglasm::Pose2D>* motions, std::vector<bool>* valid);

/// The map picture `png`: every scan (converted by `conversion`) drawn at the laser poses of the laser
/// odometry and, beside them, of the wheel odometry started at the same pose (gnuplot).
bool writeScanMap(const std::string& png, const std::string& title, const BagData& data,
                  const hglasm::ScanConversionOptions& conversion,
                  const std::vector<hglasm::StampedPose>& laser_trajectory,
                  const std::vector<hglasm::StampedPose>& wheel_trajectory, std::string* error);

}  // namespace hglasm_odometry
