#include "hglasm_odometry/core/scan.h"

#include <algorithm>
#include <cmath>

#include "hglasm_odometry/core/parameter_source.h"

namespace hglasm {

std::string inconsistency(const ScanConversionOptions& options, const std::string& prefix) {
  if (options.max_range <= options.min_range) {
    return constraintError(prefix, "scan/max_range", "be greater than", "scan/min_range",
                           ParameterValue::ofDouble(options.min_range),
                           ParameterValue::ofDouble(options.max_range));
  }
  return "";
}

const char* toString(ScanError error) {
  switch (error) {
    case ScanError::kNone:
      return "ok";
    case ScanError::kNoBeams:
      return "scan has no beams";
    case ScanError::kBadAngles:
      return "angle_min or angle_increment is not finite, or the increment is zero";
    case ScanError::kBadRangeLimits:
      return "range_min/range_max are NaN or range_max < range_min";
  }
  return "unknown";
}

Scan scanFromRanges(const RangeScan& input, const ScanConversionOptions& options, ScanError* error) {
  Scan scan;
  scan.beam_count = static_cast<int>(input.ranges.size());
  ScanError status = ScanError::kNone;
  if (input.ranges.empty()) {
    status = ScanError::kNoBeams;
  } else if (!std::isfinite(input.angle_min) || !std::isfinite(input.angle_increment) ||
             (input.ranges.size() > 1 && input.angle_increment == 0.0)) {
    status = ScanError::kBadAngles;
  } else if (std::isnan(input.range_min) || std::isnan(input.range_max) ||
             input.range_max < input.range_min) {
    status = ScanError::kBadRangeLimits;
  }
  if (error) *error = status;
  if (status != ScanError::kNone) {
    scan.invalid_count = scan.beam_count;
    return scan;
  }

  const double lower = std::max({input.range_min, options.min_range, 0.0});
  const double upper = std::min(input.range_max, options.max_range);
  const int step = std::max(1, options.beam_step);
  const double sign = options.mirror ? -1.0 : 1.0;
  scan.points.reserve(input.ranges.size() / step + 1);
  scan.beam_index.reserve(input.ranges.size() / step + 1);
  for (int i = 0; i < scan.beam_count; i += step) {
    const double range = input.ranges[i];
    // REP-117: NaN, +-inf and out-of-limit readings carry no position; zero is never a return.
    if (!std::isfinite(range) || range <= 0.0 || range < lower || range > upper) continue;
    const double angle = sign * (input.angle_min + i * input.angle_increment);
    scan.points.emplace_back(range * std::cos(angle), range * std::sin(angle));
    scan.beam_index.push_back(i);
  }
  scan.invalid_count = scan.beam_count - static_cast<int>(scan.points.size());
  const double sweep = scanSweepTime(input.time_increment, scan.beam_count, options);
  if (sweep != 0.0) {
    // The scan's own increment exactly when it is the one used; else the configured sweep spread evenly.
    const bool own = sweep == input.time_increment * static_cast<double>(scan.beam_count - 1);
    scan.time_increment = own ? input.time_increment : sweep / (scan.beam_count - 1);
  }
  return scan;
}

double scanSweepTime(double time_increment, std::size_t beam_count, const ScanConversionOptions& options) {
  if (beam_count < 2) return 0.0;
  // A sweep longer than a second is no 2D laser's: such a time_increment is a driver's mistake.
  const double stated_sweep = time_increment * static_cast<double>(beam_count - 1);
  if (std::isfinite(time_increment) && time_increment != 0.0 && std::abs(stated_sweep) <= kMaxSweepTime) {
    return stated_sweep;
  }
  if (std::isfinite(options.sweep_time) && options.sweep_time > 0.0 && options.sweep_time <= kMaxSweepTime) {
    return options.sweep_time;
  }
  return 0.0;
}

std::vector<std::uint8_t> ReferencePoints::sameScanAsNext() const {
  std::vector<std::uint8_t> same(points.size(), 1);
  if (!points.empty()) same.back() = 0;
  for (const std::size_t start : scan_starts) {
    if (start > 0 && start <= points.size()) same[start - 1] = 0;
  }
  return same;
}

namespace {

constexpr double kMaxJoinStep = 2.0 * M_PI / 180.0;

/// Median bearing step between consecutive finite points of reference[begin, end), seen from `origin`.
double medianAngularStep(const std::vector<Eigen::Vector2d>& points, std::size_t begin, std::size_t end,
                         const Eigen::Vector2d& origin) {
  std::vector<double> steps;
  steps.reserve(end > begin ? end - begin : 0);
  for (std::size_t i = begin; i + 1 < end; ++i) {
    if (!points[i].allFinite() || !points[i + 1].allFinite()) continue;
    const Eigen::Vector2d a = points[i] - origin, b = points[i + 1] - origin;
    steps.push_back(std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b))));
  }
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

/// Records the points of `reference` from `start` on as a scan seen from `origin`.
void addScan(ReferencePoints* reference, std::size_t start, const Eigen::Vector2d& origin) {
  reference->scan_starts.push_back(start);
  reference->scan_origins.push_back(origin);
  // Cached while every scan came through here (angularStep() computes what is not cached).
  std::vector<double>& steps = reference->scan_steps;
  if (steps.size() + 1 == reference->scan_starts.size()) {
    steps.push_back(medianAngularStep(reference->points, start, reference->points.size(), origin));
  } else {
    steps.clear();
  }
}

}  // namespace

double angularStep(const ReferencePoints& reference, std::size_t scan) {
  if (scan < reference.scan_steps.size()) return reference.scan_steps[scan];
  if (scan >= reference.scan_starts.size()) return 0.0;
  return medianAngularStep(reference.points, reference.scan_starts[scan], reference.scanEnd(scan),
                           reference.scanOrigin(scan));
}

void ReferencePoints::append(const std::vector<Eigen::Vector2d>& scan_points, const Pose2D& pose) {
  if (scan_points.empty()) return;
  const std::size_t start = points.size();
  // pose * point, with the rotation's cosine and sine computed once.
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  points.reserve(start + scan_points.size());
  for (const auto& point : scan_points) {
    points.emplace_back(pose.x + c * point.x() - s * point.y(), pose.y + s * point.x() + c * point.y());
  }
  addScan(this, start, Eigen::Vector2d(pose.x, pose.y));
}

void ReferencePoints::appendMoved(const std::vector<Eigen::Vector2d>& moved_points,
                                  const Eigen::Vector2d& origin) {
  if (moved_points.empty()) return;
  const std::size_t start = points.size();
  points.insert(points.end(), moved_points.begin(), moved_points.end());
  addScan(this, start, origin);
}

std::vector<std::uint8_t> joinSurfaces(const ReferencePoints& reference, const SurfaceOptions& options,
                                       std::size_t first_scan) {
  const std::vector<Eigen::Vector2d>& points = reference.points;
  std::vector<std::uint8_t> joins(points.size(), 0);
  if (!(options.max_gap > 0.0)) return joins;
  const double incidence = options.max_incidence;
  const double oblique = incidence > 0.0 && incidence < 0.5 * M_PI ? 1.0 / std::cos(incidence) : 0.0;
  for (std::size_t scan = first_scan; scan < reference.scan_starts.size(); ++scan) {
    const Eigen::Vector2d origin = reference.scanOrigin(scan);
    // Capped: a scan of a few scattered points has no beam spacing (no 2D laser is coarser than ~1 deg).
    const double step_gap = std::min(angularStep(reference, scan), kMaxJoinStep) * oblique;
    for (std::size_t i = reference.scan_starts[scan]; i + 1 < reference.scanEnd(scan); ++i) {
      const Eigen::Vector2d& a = points[i];
      const Eigen::Vector2d& b = points[i + 1];
      if (!a.allFinite() || !b.allFinite()) continue;
      const double range = std::min((a - origin).norm(), (b - origin).norm());
      const double max_gap = options.max_gap + range * step_gap;
      joins[i] = (b - a).squaredNorm() < max_gap * max_gap ? 1 : 0;
    }
  }
  return joins;
}

Scan selectBeams(const Scan& scan, int parity) {
  Scan out;
  out.beam_count = scan.beam_count;
  out.time_increment = scan.time_increment;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if ((scan.beam_index[i] & 1) == (parity & 1)) {
      out.points.push_back(scan.points[i]);
      out.beam_index.push_back(scan.beam_index[i]);
    }
  }
  out.invalid_count = 0;
  return out;
}

void transformPoints(const std::vector<Eigen::Vector2d>& points, const Pose2D& pose,
                     std::vector<Eigen::Vector2d>* moved) {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  moved->resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d& point = points[i];
    (*moved)[i] =
        Eigen::Vector2d(pose.x + c * point.x() - s * point.y(), pose.y + s * point.x() + c * point.y());
  }
}

Scan transformScan(const Scan& scan, const Pose2D& pose) {
  Scan out = scan;
  for (auto& point : out.points) point = pose * point;
  return out;
}

Scan deskewScan(const Scan& scan, const Eigen::Vector3d& velocity) {
  if (!velocity.allFinite()) return scan;
  // Constant velocity, first order: a sweep lasts milliseconds.
  return deskewScan(scan, [&velocity](double dt) {
    return Pose2D(velocity.x() * dt, velocity.y() * dt, velocity.z() * dt);
  });
}

Scan deskewScan(const Scan& scan, const std::function<Pose2D(double)>& sensor_motion) {
  Scan out = scan;
  if (!scan.hasBeamTimes()) return out;
  for (std::size_t i = 0; i < out.points.size(); ++i) {
    const Pose2D motion = sensor_motion(scan.beam_index[i] * scan.time_increment);
    if (motion.isFinite()) out.points[i] = motion * out.points[i];
  }
  return out;
}

}  // namespace hglasm
