// MbICP (Minguez, Montesano, Lamiraux 2006): ICP under the SE(2) metric sqrt(x^2 + y^2 + L^2 theta^2).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_information.h"

namespace hglasm {

struct MbicpOptions {
  double metric_l = 3.0;         ///< L of the metric, metres
  double bearing_window = 0.52;  ///< radians: candidate reference points lie within this bearing
  double max_distance = 0.30;    ///< metres: association gate on d_ap while the estimate moves
  /// metres: the gate once steps fall below settle_step_xy / settle_step_theta (the estimate has settled):
  /// the last iterations ignore moved objects and unmatched structure. <= 0: keep max_distance.
  double fine_max_distance = 0.15;
  double settle_step_xy = 0.01;      ///< metres
  double settle_step_theta = 0.005;  ///< radians
  /// Consecutive reference points form a segment if they sample one surface (SurfaceOptions: within
  /// segment_max_gap, or the gap a surface seen at up to segment_max_incidence leaves between beams).
  double segment_max_gap = 0.30;                      ///< metres
  double segment_max_incidence = 1.3962634015954636;  ///< radians (80 degrees)
  /// Robust weights instead of trimming: an association at distance d weighs 1 / (1 + d^2 / c^2) (Cauchy),
  /// c = robust_scale times the median association distance (not below robust_scale * point_noise). With
  /// 3 (about 2 sigma of Gaussian inliers) a wall seen by a tenth of the points still votes, where trimming
  /// the worst tenth would drop it whole; clutter and moved objects fade smoothly. <= 0: no weights.
  double robust_scale = 3.0;
  double trim_fraction = 1.0;  ///< keep this fraction of the best associations (1: all)
  int max_iterations = 50;
  double error_ratio = 1e-4;            ///< |E_k - E_k-1| / E_k below this counts as no progress
  double min_step_xy = 1e-4;            ///< metres: a step smaller than this counts as no progress
  double min_step_theta = 1e-4;         ///< radians
  int converged_iterations = 2;         ///< consecutive no-progress iterations to stop
  double min_association_ratio = 0.1;   ///< fail below this fraction of the new scan associated
  double degenerate_eigenvalue = 1e-6;  ///< relative: min/max eigenvalue of the normal equations
  /// M-step residual of a point associated with a reference segment (or, once settled, a segment's end
  /// point): true = its d_ap distance to the segment's line (the metric restricted to the normal; converges
  /// in a few iterations like PL-ICP), false = its d_ap distance to the closest point, as in the original
  /// MbICP (slower, linear convergence). Isolated reference points are always point-to-point.
  bool point_to_line = true;
  /// The scan's information is that of at most this many independent points. Neighbouring laser points
  /// share their errors (a wall's range bias, the reference's own noise, a moved object), so n points do
  /// not know n times more than one: sigma^2 H^-1 over hundreds of points is far too confident. Measured
  /// against the relations of the Freiburg logs (README); 0 = every point independent (sigma^2 H^-1).
  double independent_points = 0.0;
  /// metres: a laser point's own noise, weighed against where along its beam's neighbourhood the
  /// reference sampled the surface. A new point associated with an isolated reference point may truly
  /// lie anywhere between that point's neighbouring beams (|p| times the angular spacing, which grows
  /// with range): its residual across the beam counts by point_noise^2 / (point_noise^2 + spacing^2 / 12),
  /// so a sparse far point cannot turn the scan by its beam spacing. <= 0: point-to-point as MbICP.
  double point_noise = 0.01;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, MbicpOptions* options) {
  visitor.positiveNumber("mbicp/metric_l", &options->metric_l);
  visitor.number("mbicp/bearing_window", &options->bearing_window, 0.0, M_PI, true);
  visitor.positiveNumber("mbicp/max_distance", &options->max_distance);
  visitor.nonNegativeNumber("mbicp/fine_max_distance", &options->fine_max_distance);
  visitor.nonNegativeNumber("mbicp/settle_step_xy", &options->settle_step_xy);
  visitor.nonNegativeNumber("mbicp/settle_step_theta", &options->settle_step_theta);
  visitor.nonNegativeNumber("mbicp/segment_max_gap", &options->segment_max_gap);
  visitor.number("mbicp/segment_max_incidence", &options->segment_max_incidence, 0.0, 0.5 * M_PI);
  visitor.boolean("mbicp/point_to_line", &options->point_to_line);
  visitor.nonNegativeNumber("mbicp/robust_scale", &options->robust_scale);
  visitor.number("mbicp/trim_fraction", &options->trim_fraction, 0.0, 1.0, true);
  visitor.nonNegativeNumber("mbicp/point_noise", &options->point_noise);
  visitor.positiveInteger("mbicp/max_iterations", &options->max_iterations);
  visitor.nonNegativeNumber("mbicp/error_ratio", &options->error_ratio);
  visitor.nonNegativeNumber("mbicp/min_step_xy", &options->min_step_xy);
  visitor.nonNegativeNumber("mbicp/min_step_theta", &options->min_step_theta);
  visitor.positiveInteger("mbicp/converged_iterations", &options->converged_iterations);
  visitor.fraction("mbicp/min_association_ratio", &options->min_association_ratio);
  visitor.fraction("mbicp/degenerate_eigenvalue", &options->degenerate_eigenvalue);
  visitor.nonNegativeNumber("mbicp/independent_points", &options->independent_points);
}

/// A Gaussian belief about the pose being estimated (the new scan in the reference frame), e.g. the
/// motion predicted by wheel odometry: MbICP then finds the maximum a posteriori pose of scan and prior.
struct PosePrior {
  Pose2D mean;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  ///< inverse covariance of (x, y, theta)
};

enum class MbicpStatus { kConverged, kMaxIterations, kTooFewAssociations, kDegenerate };
const char* toString(MbicpStatus status);

struct MbicpResult {
  Pose2D pose;  ///< new scan's pose in the reference frame
  MbicpStatus status = MbicpStatus::kTooFewAssociations;
  int iterations = 0;
  int associations = 0;    ///< associations in the last iteration
  double rms_error = 0.0;  ///< metres, sqrt(robust-weighted mean d_ap^2) of the associations
  /// 3x3 covariance of (x, y, theta) at the final pose: sigma^2 * H^-1, where H is the point-to-line
  /// information of the final associations (each residual projected on the reference surface normal, so
  /// sliding along a featureless corridor shows as a large variance) and sigma^2 their residual variance.
  /// Eigenvalues are clamped to [1e-8, 1e4]: always finite and positive definite. With a prior, the
  /// covariance of the posterior (scan and prior).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  /// Information of the scan alone about (x, y, theta) at the final pose, calibrated (independent_points)
  /// and divided by the scan's noise scale direction by direction (setScanNoiseScale); singular along
  /// directions the scene does not constrain (a corridor's axis).
  Eigen::Matrix3d scan_information = Eigen::Matrix3d::Zero();
  /// The eigen-directions of that information before the noise scale: what the scene constrains.
  InformationDirections scan_directions;
  /// With a prior: where the scan alone would have put the pose (one scan-only step from the last
  /// iterate, on the final associations); equal to `pose` without a prior.
  Pose2D scan_only_pose;
  /// The scan alone leaves a direction unconstrained. Without a prior the status is then kDegenerate; with
  /// one the prior decides that direction and the status says whether the iterations converged.
  bool degenerate = false;
};

/// Holds the reference scan's search structure; match() may be called many times per reference.
/// Not thread-safe per instance (scratch buffers); separate instances are independent.
class Mbicp {
 public:
  explicit Mbicp(const MbicpOptions& options = {});

  void setReference(const Scan& reference);
  /// Several scans in one frame (a local map): segments join consecutive points of one scan only.
  void setReference(const ReferencePoints& reference);
  /// The same after scans were appended to the reference given last: its scans before `first_new_scan` are
  /// unchanged (same frame, same points), the rest are new. The result is that of setReference(reference),
  /// in time linear in the old points instead of a rebuild. 0: setReference().
  void extendReference(const ReferencePoints& reference, std::size_t first_new_scan);
  bool hasReference() const { return !ref_points_.empty(); }

  /// Refines `initial` (new scan in the reference frame). With a `prior` the result is the maximum a
  /// posteriori pose (scan residuals weighted by their calibrated information). Always finite numbers.
  MbicpResult match(const Scan& scan, const Pose2D& initial, const PosePrior* prior = nullptr);

  const MbicpOptions& options() const { return options_; }

  /// How far the scan's information is to be believed, direction by direction (learned by the caller):
  /// divides it along its eigen-directions in the MAP and in the result. (1, 1, 1) by default.
  void setScanNoiseScale(const ScanNoiseScale& scale) { scan_noise_scale_ = scale; }

 private:
  struct Association {
    Eigen::Vector2d point;   // new point in the reference frame (current estimate)
    Eigen::Vector2d target;  // closest point on the reference (point or segment)
    Eigen::Vector2d normal;  // reference surface normal there (zero for an isolated point)
    bool on_segment;         // target lies inside a reference segment (normal = the segment's)
    double distance_sq;      // d_ap^2
    // Isolated reference point: unit direction across its beam and the variance of where along it the
    // surface was sampled (zero otherwise).
    Eigen::Vector2d sampling_tangent;
    double sampling_variance;
    double weight;  // robust weight of the last step (1 without robust_scale)
  };
  /// The finite points of `reference`'s scans from `first_scan` on, with their segments, normals and
  /// sampling (the direction across each beam and the variance of where along it the surface was hit).
  void appendScans(const ReferencePoints& reference, std::size_t first_scan);
  /// sorted_index_, sorted_bearing_, bucket_first_ and walk_ of all reference points.
  void sortByBearing();
  /// The same after the points from `old_count` on were appended to sorted ones.
  void mergeByBearing(std::size_t old_count);
  /// Convergence bookkeeping of the settled iterations.
  struct Progress {
    double previous_error = -1.0;
    int quiet_iterations = 0;
    Pose2D previous_pose, two_poses_ago;  // estimates of the last two settled iterations
    int settled_poses = 0;
  };
  /// After a settled iteration: true once converged_iterations in a row made no progress.
  bool converged(const Eigen::Vector3d& step, const Pose2D& pose, double error, Progress* progress) const;
  /// The best association of one point so far (d_ap^2 below `best`).
  struct Candidate {
    double best = 0.0;
    int element = -1;  // reference point, or segment from it to the next; -1: none yet
    bool segment = false;
    Eigen::Vector2d target;  // the point on the element
    int entry = -1;          // the walk entry it was found at (the next iteration starts there)
  };
  /// A reference point in bearing order with its two segments, so that the walk reads memory in sequence.
  struct WalkEntry {
    Eigen::Vector2d point;
    Eigen::Vector2d to_next;        // segment index -> index + 1 (if has_next)
    Eigen::Vector2d from_previous;  // segment index - 1 -> index (if has_previous)
    double metric_inverse = 0.0;    // 1 / (|point|^2 + L^2)
    double range = 0.0;             // |point|
    double reach = 0.0;             // the longer of its two segments
    int index = 0;                  // into ref_points_
    bool has_next = false;
    bool has_previous = false;
  };
  WalkEntry walkEntry(int j) const;
  /// The association of p with its candidate's element.
  Association associationOf(const Eigen::Vector2d& p, const Candidate& candidate) const;
  void considerPoint(const Eigen::Vector2d& p, const WalkEntry& entry, Candidate* candidate) const;
  /// u_scale: 1 / (|p|^2 + L^2), the metric frozen at p.
  void considerSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& e, int j,
                       double l_sq, double u_scale, Candidate* candidate) const;
  /// The entry's point and both its segments.
  void considerEntry(const Eigen::Vector2d& p, const WalkEntry& entry, double l_sq, double u_scale,
                     Candidate* candidate) const;
  /// The best association of one point (its bearing walk), starting from `warm_element` (the element of the
  /// last iteration's walk entry, -1: none).
  void associatePoint(const Eigen::Vector2d& p, double gate_sq, int warm_entry, Candidate* candidate);
  /// The first index of sorted_bearing_ not below `bearing` (std::lower_bound).
  int walkStart(double bearing) const;
  void associate(const std::vector<Eigen::Vector2d>& moved, double gate, std::vector<Association>* out);
  /// c^2 of the robust weights for the current associations (0: no weights).
  double robustScaleSq();
  /// The d_ap metric of one association (to its segment's line, or weighed against an isolated reference
  /// point's sampling), and its squared residual under it.
  Eigen::Matrix2d associationMetric(const Association& assoc, bool settled, double l_sq,
                                    double* residual_sq) const;
  /// Trims and weighs the associations (trim_fraction, robust_scale) and solves for the increment
  /// (pose = increment * pose); false if the system has no finite solution.
  bool solveStep(const Pose2D& pose, bool settled, std::size_t min_associations, const PosePrior* prior,
                 Eigen::Vector3d* step, Eigen::Vector3d* scan_only_step, double* error);
  /// Covariance, calibrated scan information and degeneracy at the final pose from the final associations.
  void estimateUncertainty(const PosePrior* prior, MbicpResult* result) const;
  /// Share of the information of `constraints` associations that counts (independent_points).
  double informationScale(double constraints) const;

  MbicpOptions options_;
  std::vector<Eigen::Vector2d> ref_points_;    // in beam order
  std::vector<std::int8_t> ref_has_next_;      // segment from point i to i+1
  std::vector<Eigen::Vector2d> ref_normals_;   // unit surface normal at each point (zero if isolated)
  std::vector<Eigen::Vector2d> ref_tangents_;  // unit direction across each point's beam
  std::vector<double> ref_sampling_variance_;  // (range * angular spacing)^2 / 12 of each point
  std::vector<double> sorted_bearing_;         // bearings of reference points, ascending
  std::vector<int> sorted_index_;              // their indices into ref_points_
  std::vector<int> bucket_first_;  // first sorted index of each of n equal bearing buckets (n + 1 entries)
  std::vector<WalkEntry> walk_;    // the reference points in the order of sorted_bearing_
  std::vector<std::pair<double, int>> added_scratch_;  // mergeByBearing: the new points, bearing and index
  std::vector<Association> associations_;              // scratch
  Eigen::Matrix3d scan_information_ = Eigen::Matrix3d::Zero();  // of the last step, increment coordinates
  ScanNoiseScale scan_noise_scale_ = ScanNoiseScale::Ones();
  std::vector<Eigen::Vector2d> moved_;   // scratch
  std::vector<Eigen::Vector2d> points_;  // scratch: the scan's points matched
  std::vector<double> distance_sq_;      // scratch: the associations' squared distances
  std::vector<int> warm_entry_;          // per point: the walk entry of its last association (-1: none)
};

}  // namespace hglasm
