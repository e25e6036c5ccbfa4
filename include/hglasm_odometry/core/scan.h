// Laser scan geometry: polar ranges -> Cartesian points, with REP-117 validity.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

/// The polar fields of a sensor_msgs/LaserScan, without ROS. Beam i has angle
/// angle_min + i * angle_increment; the increment may be negative (descending scans).
struct RangeScan {
  std::vector<float> ranges;
  double angle_min = 0.0;
  double angle_increment = 0.0;
  double range_min = 0.0;
  double range_max = std::numeric_limits<double>::infinity();
  double time_increment = 0.0;  ///< seconds between consecutive beams (0: not known)
};

/// Longest sweep (first beam to last, seconds) taken as a scan's timing; longer ones are ignored.
constexpr double kMaxSweepTime = 1.0;

/// How a RangeScan becomes points. Ranges outside [max(range_min, min_range), min(range_max, max_range)],
/// NaN, +-inf, zero and negative ranges are invalid and never used (REP-117).
struct ScanConversionOptions {
  double min_range = 0.0;                                      ///< extra lower limit, metres
  double max_range = std::numeric_limits<double>::infinity();  ///< extra upper limit, metres
  int beam_step = 1;                                           ///< keep every n-th beam (decimation)
  bool mirror = false;  ///< negate beam angles: an upside-down laser seen from above
  /// Seconds from the first beam to the last, assumed when the scan's own time_increment is 0 or not
  /// finite (converted logs, drivers that leave it out). 0: the beams' times stay unknown.
  double sweep_time = 0.0;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, ScanConversionOptions* options) {
  visitor.nonNegativeNumber("scan/min_range", &options->min_range);
  visitor.number("scan/max_range", &options->max_range, 0.0, std::numeric_limits<double>::infinity(), true,
                 true);
  visitor.integer("scan/beam_step", &options->beam_step, 1, 100);
  visitor.number("scan/sweep_time", &options->sweep_time, 0.0, kMaxSweepTime);
}

/// Constraints between its parameters, checked once every layer is applied: "" if met, else one line
/// naming the parameter after `prefix` ("~").
std::string inconsistency(const ScanConversionOptions& options, const std::string& prefix);

/// Valid points of one scan in the sensor frame, in beam order.
struct Scan {
  std::vector<Eigen::Vector2d> points;
  std::vector<int> beam_index;  ///< original beam index of each point (consecutive beams are neighbours)
  int beam_count = 0;           ///< beams in the source scan, valid or not
  int invalid_count = 0;        ///< beams dropped as invalid
  /// Beam i was measured i * time_increment seconds after the scan's stamp (sensor_msgs/LaserScan: the
  /// stamp is the first beam's time). 0: not known.
  double time_increment = 0.0;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool hasBeamTimes() const { return std::isfinite(time_increment) && time_increment != 0.0; }
};

/// Reference points made of one or several scans in one frame, each scan's points in beam order.
/// Consecutive points of the same scan may be joined into a surface (lookup-table gaps, MbICP segments);
/// points of different scans never are.
struct ReferencePoints {
  std::vector<Eigen::Vector2d> points;
  std::vector<std::size_t> scan_starts;       ///< index of each scan's first point, ascending
  std::vector<Eigen::Vector2d> scan_origins;  ///< each scan's sensor position in this set's frame
  /// Each scan's angular step (angularStep()), computed once when it is appended (empty if some scan was
  /// not appended with append()).
  std::vector<double> scan_steps;

  /// Appends a scan's points moved by `pose` (the scan's frame in this set's frame) as a new scan.
  void append(const std::vector<Eigen::Vector2d>& scan_points, const Pose2D& pose = Pose2D());
  /// The same with the points already in this set's frame (transformPoints()), the sensor at `origin`.
  void appendMoved(const std::vector<Eigen::Vector2d>& moved_points, const Eigen::Vector2d& origin);

  /// For each point: 1 if the next point belongs to the same scan.
  std::vector<std::uint8_t> sameScanAsNext() const;
  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  /// One past the last point of scan `scan`.
  std::size_t scanEnd(std::size_t scan) const {
    return scan + 1 < scan_starts.size() ? scan_starts[scan + 1] : points.size();
  }
  /// Sensor position of scan `scan` (the set's origin if it was not recorded).
  Eigen::Vector2d scanOrigin(std::size_t scan) const {
    return scan < scan_origins.size() ? scan_origins[scan] : Eigen::Vector2d::Zero();
  }
  void clear() {
    points.clear();
    scan_starts.clear();
    scan_origins.clear();
    scan_steps.clear();
  }
};

/// When two consecutive points of one scan count as samples of one surface (the lookup table joins them
/// with a line of samples, MbICP with a segment).
struct SurfaceOptions {
  double max_gap = 0.30;  ///< metres: neighbours this close are joined at any range; <= 0: never join
  /// radians: farther neighbours are joined if a flat surface seen this obliquely would leave their gap
  /// between neighbouring beams (range * the scan's angular step / cos(max_incidence)), so the rule
  /// follows each laser's resolution. <= 0: max_gap alone.
  double max_incidence = 1.3962634015954636;  // 80 degrees
};

/// Median bearing step between consecutive finite points of scan `scan` of `reference`, seen from its
/// origin: the scan's angular resolution (missing beams widen some steps, not the median). 0 with fewer
/// than two points.
double angularStep(const ReferencePoints& reference, std::size_t scan);

/// For each point of `reference`: 1 if it and the next point are joined under `options` (same scan, both
/// finite, the gap small enough), else 0. Scans before `first_scan` are left at 0 (not examined).
std::vector<std::uint8_t> joinSurfaces(const ReferencePoints& reference, const SurfaceOptions& options,
                                       std::size_t first_scan = 0);

/// Why a RangeScan could not be converted at all (its points are then empty).
enum class ScanError { kNone, kNoBeams, kBadAngles, kBadRangeLimits };
const char* toString(ScanError error);

/// Converts polar ranges into Cartesian points. Never throws; a structurally broken scan (no beams,
/// non-finite or zero increment with several beams, ...) yields an empty Scan and sets *error.
Scan scanFromRanges(const RangeScan& ranges, const ScanConversionOptions& options = {},
                    ScanError* error = nullptr);

/// The points whose original beam index has the given parity (0 = even beams, 1 = odd beams).
Scan selectBeams(const Scan& scan, int parity);

/// Applies `pose` to every point (beam indices kept).
Scan transformScan(const Scan& scan, const Pose2D& pose);

/// *moved = pose * each of `points` (the same numbers as Pose2D's operator, its cosine and sine once).
void transformPoints(const std::vector<Eigen::Vector2d>& points, const Pose2D& pose,
                     std::vector<Eigen::Vector2d>* moved);

/// Seconds from a scan's first beam to its last (signed like time_increment): its own time_increment when
/// that gives a sweep of at most kMaxSweepTime, else options.sweep_time, else 0 (not known).
double scanSweepTime(double time_increment, std::size_t beam_count, const ScanConversionOptions& options);

/// Motion compensation: moves every point to where the sensor would have seen it at the scan's stamp,
/// the sensor moving with `velocity` (vx, vy in m/s, omega in rad/s, in its own frame) during the sweep.
/// Returns the scan unchanged when its beams' times are not known (time_increment 0).
Scan deskewScan(const Scan& scan, const Eigen::Vector3d& velocity);

/// The same with the sensor's pose at each beam given: `sensor_motion(t)` is the sensor at t seconds after
/// the stamp, in its frame at the stamp (a turn rate that changes during the sweep, from a gyro).
Scan deskewScan(const Scan& scan, const std::function<Pose2D(double)>& sensor_motion);

}  // namespace hglasm
