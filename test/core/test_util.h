// Shared helpers of the core tests, the rostests and the benchmark: a simulated laser in polygonal worlds,
// simulated wheels, angle and pose error helpers, and the loader of the real-scan fixtures in test/data.
// Header-only, ROS-free.
//
// The simulation deliberately does not use the core (no Pose2D operators, no scanFromRanges), so a bug in
// the core cannot cancel itself out in the tests.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm_test {

constexpr double kPi = 3.14159265358979323846;

inline double deg(double degrees) { return degrees * kPi / 180.0; }

/// Shortest signed angle from b to a, in [-pi, pi] (independent of hglasm::normalizeAngle).
inline double angleDiff(double a, double b) { return std::atan2(std::sin(a - b), std::cos(a - b)); }

inline double translationError(const hglasm::Pose2D& estimate, const hglasm::Pose2D& truth) {
  return std::hypot(estimate.x - truth.x, estimate.y - truth.y);
}
inline double rotationError(const hglasm::Pose2D& estimate, const hglasm::Pose2D& truth) {
  return std::abs(angleDiff(estimate.theta, truth.theta));
}

/// Poses built without hglasm::normalizeAngle (theta stored as given).
inline hglasm::Pose2D rawPose(double x, double y, double theta) {
  hglasm::Pose2D pose;
  pose.x = x;
  pose.y = y;
  pose.theta = theta;
  return pose;
}

/// a * b written out by hand (b expressed in a's frame).
inline hglasm::Pose2D composeByHand(const hglasm::Pose2D& a, const hglasm::Pose2D& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return rawPose(a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y,
                 std::atan2(std::sin(a.theta + b.theta), std::cos(a.theta + b.theta)));
}

/// a^-1 * b written out by hand: the pose of b in a's frame.
inline hglasm::Pose2D relativeByHand(const hglasm::Pose2D& a, const hglasm::Pose2D& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const double dx = b.x - a.x, dy = b.y - a.y;
  return rawPose(c * dx + s * dy, -s * dx + c * dy, angleDiff(b.theta, a.theta));
}

inline bool allFinite(const Eigen::Matrix3d& m) { return m.allFinite(); }

/// Finite, symmetric (to rounding) and positive semi-definite.
inline bool isValidCovariance(const Eigen::Matrix3d& m) {
  if (!m.allFinite()) return false;
  if ((m - m.transpose()).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + m.cwiseAbs().maxCoeff())) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(0.5 * (m + m.transpose()));
  return solver.eigenvalues().minCoeff() >= -1e-12;
}

// ------------------------------------------------------------------ polygonal worlds

struct Segment {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
};
using World = std::vector<Segment>;

/// Adds a closed polygon (the last vertex joins the first).
inline void addPolygon(World* world, const std::vector<Eigen::Vector2d>& vertices) {
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    world->push_back({vertices[i], vertices[(i + 1) % vertices.size()]});
  }
}

inline void addBox(World* world, double cx, double cy, double half_x, double half_y) {
  addPolygon(world, {{cx - half_x, cy - half_y},
                     {cx + half_x, cy - half_y},
                     {cx + half_x, cy + half_y},
                     {cx - half_x, cy + half_y}});
}

/// An asymmetric L-shaped room (about 11 m x 9 m) with a few boxes and a slanted wall, so that a scan taken
/// anywhere in the box |x|, |y| <= 2 m around the origin determines its pose uniquely. The origin is free.
inline World room() {
  World world;
  addPolygon(
      &world,
      {{-5.0, -4.0}, {6.0, -4.0}, {6.0, 1.0}, {4.0, 1.0}, {4.0, 5.0}, {-3.0, 5.0}, {-3.0, 3.0}, {-5.0, 3.0}});
  addBox(&world, 2.0, -2.6, 0.4, 0.3);
  addBox(&world, -2.2, 1.6, 0.3, 0.3);
  addBox(&world, 1.0, 3.4, 0.2, 0.2);
  addBox(&world, 4.8, -1.0, 0.3, 0.5);
  world.push_back({{-4.5, -1.0}, {-3.6, -3.2}});  // a free-standing slanted panel
  return world;
}

/// Two parallel walls y = +-half_width, |x| <= half_length: with range_max well below half_length a scan
/// cannot see where it is along the corridor.
inline World corridor(double half_width = 1.0, double half_length = 200.0) {
  World world;
  world.push_back({{-half_length, -half_width}, {half_length, -half_width}});
  world.push_back({{-half_length, half_width}, {half_length, half_width}});
  return world;
}

/// Distance along the ray to the nearest segment, or +inf.
inline double castRay(const World& world, const Eigen::Vector2d& origin, const Eigen::Vector2d& direction) {
  double best = std::numeric_limits<double>::infinity();
  for (const Segment& segment : world) {
    const Eigen::Vector2d edge = segment.b - segment.a;
    const double denom = direction.x() * edge.y() - direction.y() * edge.x();
    if (std::abs(denom) < 1e-12) continue;  // parallel
    const Eigen::Vector2d to_a = segment.a - origin;
    const double t = (to_a.x() * edge.y() - to_a.y() * edge.x()) / denom;
    const double u = (to_a.x() * direction.y() - to_a.y() * direction.x()) / denom;
    if (t > 1e-9 && u >= 0.0 && u <= 1.0 && t < best) best = t;
  }
  return best;
}

// ------------------------------------------------------------------ paths

/// A 1.5 m square driven at 0.5 m/s, turning left on the spot at each corner at `turn_rate` rad/s
/// (constant, from standstill to standstill), from the identity pose; it stays clear of the room's boxes.
inline std::function<hglasm::Pose2D(double)> squareWithSpins(double turn_rate) {
  constexpr double kSide = 1.5, kSpeed = 0.5;
  const double drive_time = kSide / kSpeed, turn_time = (kPi / 2) / turn_rate;
  return [=](double t) {
    const double leg = drive_time + turn_time;
    const double lap = std::fmod(std::max(t, 0.0), 4.0 * leg);
    const int side = static_cast<int>(lap / leg);
    const double within = lap - side * leg;
    const Eigen::Vector2d corners[4] = {{0.0, 0.0}, {kSide, 0.0}, {kSide, kSide}, {0.0, kSide}};
    const Eigen::Vector2d start = corners[side], end = corners[(side + 1) % 4];
    const double heading = side * kPi / 2;
    if (within < drive_time) {
      const Eigen::Vector2d at = start + (end - start) * (within / drive_time);
      return rawPose(at.x(), at.y(), angleDiff(heading, 0.0));
    }
    return rawPose(end.x(), end.y(), angleDiff(heading + turn_rate * (within - drive_time), 0.0));
  };
}

/// The yaw rate (rad/s) of `path` at t: a central difference over 1 ms (the paths are piecewise smooth).
inline double yawRate(const std::function<hglasm::Pose2D(double)>& path, double t) {
  return angleDiff(path(t + 5e-4).theta, path(t - 5e-4).theta) / 1e-3;
}

// ------------------------------------------------------------------ the simulated wheels

/// The wheel odometry of a robot driving `path`, a sample every kPeriod s after `start`: the path itself
/// (exact wheels), or after setErrors the path's increments integrated from `start_pose` with a scale
/// error, a heading drift per metre and a share of every turn (worn or slipping wheels). The robots of the
/// core tests and the rostests all drive their wheels with it.
class SimulatedWheels {
 public:
  static constexpr double kPeriod = 0.02;  // 50 Hz

  explicit SimulatedWheels(std::function<hglasm::Pose2D(double)> path, double start = 0.0,
                           const hglasm::Pose2D& start_pose = hglasm::Pose2D())
      : path_(std::move(path)), time_(start), pose_(start_pose) {}

  /// Integrated wheels from now on, from the pose they report now.
  void setErrors(double scale_error, double drift_per_metre, double turn_scale) {
    integrated_ = true;
    scale_error_ = scale_error;
    drift_per_metre_ = drift_per_metre;
    turn_scale_ = turn_scale;
  }
  /// Exact wheels again.
  void setExact() { integrated_ = false; }
  /// The wheels report this path from now on.
  void setPath(std::function<hglasm::Pose2D(double)> path) { path_ = std::move(path); }
  /// Samples start again after `start`, integrated ones from the path's pose there.
  void restart(double start) {
    time_ = start;
    pose_ = path_(start);
  }

  double time() const { return time_; }
  /// The last sample of integrated wheels.
  const hglasm::Pose2D& pose() const { return pose_; }

  /// Calls sample(time, pose) for each sample up to `until` (1 ns tolerance).
  template <typename Sample>
  void advance(double until, const Sample& sample) {
    while (time_ + kPeriod <= until + 1e-9) {
      const double before = time_;
      time_ += kPeriod;
      if (!integrated_) {
        sample(time_, path_(time_));
        continue;
      }
      const hglasm::Pose2D motion = relativeByHand(path_(before), path_(time_));
      const double distance = std::hypot(motion.x, motion.y);
      pose_ = composeByHand(pose_, rawPose((1.0 + scale_error_) * motion.x, (1.0 + scale_error_) * motion.y,
                                           turn_scale_ * motion.theta + drift_per_metre_ * distance));
      sample(time_, pose_);
    }
  }

 private:
  std::function<hglasm::Pose2D(double)> path_;
  double time_;
  hglasm::Pose2D pose_;
  bool integrated_ = false;
  double scale_error_ = 0.0;
  double drift_per_metre_ = 0.0;
  double turn_scale_ = 1.0;
};

// ------------------------------------------------------------------ the simulated laser

struct LaserSpec {
  int beams = 361;
  double angle_min = -kPi / 2;
  double angle_increment = kPi / 360;
  double range_min = 0.05;
  double range_max = 30.0;
};

/// A laser covering `fov` radians with `beams` beams centred on the x axis. A 360-degree laser
/// (fov >= 2 pi) starts at -pi with increment 2 pi / beams. `descending` scans from left to right.
inline LaserSpec laserSpec(double fov, int beams, bool descending = false, double range_max = 30.0) {
  LaserSpec spec;
  spec.beams = beams;
  spec.range_max = range_max;
  const bool full_circle = fov >= 2.0 * kPi - 1e-9;
  const double increment = full_circle ? 2.0 * kPi / beams : (beams > 1 ? fov / (beams - 1) : 0.0);
  const double first = full_circle ? -kPi : -0.5 * fov;
  if (descending) {
    spec.angle_min = first + increment * (beams - 1);
    spec.angle_increment = -increment;
  } else {
    spec.angle_min = first;
    spec.angle_increment = increment;
  }
  return spec;
}

/// The default test laser: 180 degrees, 361 beams (0.5 degree), like the laserazos data.
inline LaserSpec halfCircleLaser() { return laserSpec(kPi, 361); }
/// A 360-degree laser with 360 beams starting at -pi (the +-pi seam is between the last and first beam).
inline LaserSpec fullCircleLaser(int beams = 360) { return laserSpec(2.0 * kPi, beams); }

/// Ranges of a laser at `pose` (world frame) as a sensor would publish them: +inf where nothing is hit
/// within range_max (REP-117).
inline hglasm::RangeScan simulateRanges(const World& world, const hglasm::Pose2D& pose,
                                        const LaserSpec& spec) {
  hglasm::RangeScan scan;
  scan.angle_min = spec.angle_min;
  scan.angle_increment = spec.angle_increment;
  scan.range_min = spec.range_min;
  scan.range_max = spec.range_max;
  scan.ranges.resize(spec.beams);
  const Eigen::Vector2d origin(pose.x, pose.y);
  for (int i = 0; i < spec.beams; ++i) {
    const double angle = pose.theta + spec.angle_min + i * spec.angle_increment;
    const double range = castRay(world, origin, Eigen::Vector2d(std::cos(angle), std::sin(angle)));
    scan.ranges[i] =
        range <= spec.range_max ? static_cast<float>(range) : std::numeric_limits<float>::infinity();
  }
  return scan;
}

/// A laser that may move while it sweeps: beam i is measured from `sensor_pose(i)` (world frame) and
/// expressed in that pose's frame, converted here (not by the core) with double precision.
template <typename PoseOfBeam>
hglasm::Scan simulateSweep(const World& world, PoseOfBeam sensor_pose, const LaserSpec& spec) {
  hglasm::Scan scan;
  scan.beam_count = spec.beams;
  for (int i = 0; i < spec.beams; ++i) {
    const hglasm::Pose2D pose = sensor_pose(i);
    const double local = spec.angle_min + i * spec.angle_increment;
    const double angle = pose.theta + local;
    const double range =
        castRay(world, Eigen::Vector2d(pose.x, pose.y), Eigen::Vector2d(std::cos(angle), std::sin(angle)));
    if (!(range >= spec.range_min && range <= spec.range_max)) {
      ++scan.invalid_count;
      continue;
    }
    scan.points.emplace_back(range * std::cos(local), range * std::sin(local));
    scan.beam_index.push_back(i);
  }
  return scan;
}

/// The scan of simulateRanges as points in the sensor frame (every beam at the same instant).
inline hglasm::Scan simulateScan(const World& world, const hglasm::Pose2D& pose, const LaserSpec& spec) {
  return simulateSweep(
      world, [&pose](int) { return pose; }, spec);
}

/// Moves points by `pose` without the core (pose * p).
inline std::vector<Eigen::Vector2d> movePoints(const std::vector<Eigen::Vector2d>& points,
                                               const hglasm::Pose2D& pose) {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  std::vector<Eigen::Vector2d> out;
  out.reserve(points.size());
  for (const Eigen::Vector2d& p : points) {
    out.emplace_back(pose.x + c * p.x() - s * p.y(), pose.y + s * p.x() + c * p.y());
  }
  return out;
}

/// The papers' protocol: the new scan is `scan` seen from a sensor whose pose in the reference frame is
/// `truth`, i.e. its points are truth^-1 * p. A matcher started at the identity must return `truth`.
inline hglasm::Scan displacedScan(const hglasm::Scan& scan, const hglasm::Pose2D& truth) {
  hglasm::Scan out = scan;
  const double c = std::cos(truth.theta), s = std::sin(truth.theta);
  for (Eigen::Vector2d& p : out.points) {
    const double dx = p.x() - truth.x, dy = p.y() - truth.y;
    p = Eigen::Vector2d(c * dx + s * dy, -s * dx + c * dy);
  }
  return out;
}

/// Odd or even beams of a scan, by original beam index (independent of hglasm::selectBeams).
inline hglasm::Scan beamsWithParity(const hglasm::Scan& scan, int parity) {
  hglasm::Scan out;
  out.beam_count = scan.beam_count;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (scan.beam_index[i] % 2 == parity) {
      out.points.push_back(scan.points[i]);
      out.beam_index.push_back(scan.beam_index[i]);
    }
  }
  return out;
}

// ------------------------------------------------------------------ real-scan fixtures (test/data)

struct RealScan {
  double stamp = 0.0;
  hglasm::RangeScan ranges;
  bool has_odometry = false;
  hglasm::Pose2D odometry;  ///< base_link in odom at the scan stamp
};

inline std::string sourceDir() {
#ifdef HGLASM_SOURCE_DIR
  return HGLASM_SOURCE_DIR;
#else
  return ".";
#endif
}

inline std::string fixturePath(const std::string& name) { return sourceDir() + "/test/data/" + name; }
inline std::string datasetPath(const std::string& relative) {
  return sourceDir() + "/../shared/datasets/" + relative;
}

/// Reads a fixture written by test/data/extract_scans.py. Empty on a missing or malformed file.
/// strtod is used because it reads "nan" and "inf" (operator>> does not).
inline std::vector<RealScan> loadScanFixture(const std::string& path) {
  std::vector<RealScan> scans;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<double> values;
    std::string token;
    while (fields >> token) values.push_back(std::strtod(token.c_str(), nullptr));
    if (values.size() < 9) return {};
    RealScan scan;
    scan.stamp = values[0];
    scan.ranges.angle_min = values[1];
    scan.ranges.angle_increment = values[2];
    scan.ranges.range_min = values[3];
    scan.ranges.range_max = values[4];
    scan.has_odometry = std::isfinite(values[5]) && std::isfinite(values[6]) && std::isfinite(values[7]);
    scan.odometry = rawPose(values[5], values[6], values[7]);
    const std::size_t count = static_cast<std::size_t>(values[8]);
    if (values.size() != 9 + count) return {};
    for (std::size_t i = 0; i < count; ++i) scan.ranges.ranges.push_back(static_cast<float>(values[9 + i]));
    scans.push_back(scan);
  }
  return scans;
}

}  // namespace hglasm_test
