// MbICP (Minguez, Montesano, Lamiraux 2006): ICP under the SE(2) metric sqrt(x^2 + y^2 + L^2 theta^2).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

struct MbicpOptions {
  double metric_l = 3.0;              ///< L of the metric, metres
  double bearing_window = 0.52;       ///< radians: candidate reference points lie within this bearing
  double max_distance = 0.30;         ///< metres: association gate on d_ap while the estimate moves
  /// metres: the gate once steps fall below settle_step_xy / settle_step_theta (the estimate has settled):
  /// the last iterations ignore moved objects and unmatched structure. <= 0: keep max_distance.
  double fine_max_distance = 0.15;
  double settle_step_xy = 0.01;       ///< metres
  double settle_step_theta = 0.005;   ///< radians
  /// Consecutive reference points form a segment if they are closer than
  /// segment_max_gap + segment_gap_per_metre * range (beams diverge with range).
  double segment_max_gap = 0.30;      ///< metres
  double segment_gap_per_metre = 0.10;
  double trim_fraction = 0.95;        ///< keep this fraction of the best associations
  int max_iterations = 50;
  double error_ratio = 1e-4;          ///< |E_k - E_k-1| / E_k below this counts as no progress
  double min_step_xy = 1e-4;          ///< metres: a step smaller than this counts as no progress
  double min_step_theta = 1e-4;       ///< radians
  int converged_iterations = 2;       ///< consecutive no-progress iterations to stop
  double min_association_ratio = 0.1; ///< fail below this fraction of the new scan associated
  double degenerate_eigenvalue = 1e-6;  ///< relative: min/max eigenvalue of the normal equations
  /// M-step residual of a point associated with a reference segment (or, once settled, a segment's end
  /// point): true = its d_ap distance to the segment's line (the metric restricted to the normal; converges
  /// in a few iterations like PL-ICP), false = its d_ap distance to the closest point, as in the original
  /// MbICP (slower, linear convergence). Isolated reference points are always point-to-point.
  bool point_to_line = true;
};

enum class MbicpStatus { kConverged, kMaxIterations, kTooFewAssociations, kDegenerate };
const char* toString(MbicpStatus status);

struct MbicpResult {
  Pose2D pose;                         ///< new scan's pose in the reference frame
  MbicpStatus status = MbicpStatus::kTooFewAssociations;
  int iterations = 0;
  int associations = 0;                ///< associations kept (after trimming) in the last iteration
  double rms_error = 0.0;              ///< metres, sqrt(mean d_ap^2) of kept associations
  /// 3x3 covariance of (x, y, theta) at the final pose: sigma^2 * H^-1, where H is the point-to-line
  /// information of the final associations (each residual projected on the reference surface normal, so
  /// sliding along a featureless corridor shows as a large variance) and sigma^2 their residual variance.
  /// Eigenvalues are clamped to [1e-8, 1e4]: always finite and positive definite.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

/// Holds the reference scan's search structure; match() may be called many times per reference.
/// Not thread-safe per instance (scratch buffers); separate instances are independent.
class Mbicp {
 public:
  explicit Mbicp(const MbicpOptions& options = {});

  void setReference(const Scan& reference);
  bool hasReference() const { return !ref_points_.empty(); }

  /// Refines `initial` (new scan in the reference frame). Always returns finite numbers.
  MbicpResult match(const Scan& scan, const Pose2D& initial);

  const MbicpOptions& options() const { return options_; }

 private:
  struct Association {
    Eigen::Vector2d point;   // new point in the reference frame (current estimate)
    Eigen::Vector2d target;  // closest point on the reference (point or segment)
    Eigen::Vector2d normal;  // reference surface normal there (zero for an isolated point)
    bool on_segment;         // target lies inside a reference segment (normal = the segment's)
    double distance_sq;      // d_ap^2
  };
  void associate(const std::vector<Eigen::Vector2d>& moved, double gate, std::vector<Association>* out) const;

  MbicpOptions options_;
  std::vector<Eigen::Vector2d> ref_points_;  // in beam order
  std::vector<std::int8_t> ref_has_next_;    // segment from point i to i+1
  std::vector<Eigen::Vector2d> ref_normals_; // unit surface normal at each point (zero if isolated)
  std::vector<double> sorted_bearing_;       // bearings of reference points, ascending
  std::vector<int> sorted_index_;            // their indices into ref_points_
  std::vector<Association> associations_;    // scratch
  std::vector<Eigen::Vector2d> moved_;       // scratch
};

}  // namespace hglasm
