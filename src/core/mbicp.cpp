#include "hglasm_odometry/core/mbicp.h"

#include "hglasm_odometry/core/fast_math.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace hglasm {
namespace {

constexpr double kMinVariance = 1e-8;
constexpr double kMaxVariance = 1e4;
constexpr double kNoiseFloor = 1e-4;  // m^2: residuals never count as more precise than 1 cm

/// d pose / d increment for pose' = increment * pose (the increment applied in the reference frame).
Eigen::Matrix3d incrementToPose(const Pose2D& pose) {
  Eigen::Matrix3d g = Eigen::Matrix3d::Identity();
  g(0, 2) = -pose.y;
  g(1, 2) = pose.x;
  return g;
}

Eigen::Vector2d unitNormal(const Eigen::Vector2d& direction) {
  const double length = direction.norm();
  if (!(length > 0.0)) return Eigen::Vector2d::Zero();
  return Eigen::Vector2d(-direction.y(), direction.x()) / length;
}

/// Squared metric-based distance between a new point p and a reference point q (the MbICP d_ap, with the
/// rotation linearised): |p - q|^2 - ((p - q) x q)^2 / (|q|^2 + L^2).
double dapSquared(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double l_sq) {
  const Eigen::Vector2d d = p - q;
  const double cross = d.x() * q.y() - d.y() * q.x();
  return d.squaredNorm() - cross * cross / (q.squaredNorm() + l_sq);
}

/// Clamps the eigenvalues of a symmetric matrix into [low, high].
Eigen::Matrix3d clampEigenvalues(const Eigen::Matrix3d& matrix, double low, double high) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(matrix);
  if (solver.info() != Eigen::Success || !solver.eigenvalues().allFinite()) {
    return Eigen::Matrix3d::Identity() * high;
  }
  const Eigen::Vector3d clamped = solver.eigenvalues().cwiseMax(low).cwiseMin(high);
  return solver.eigenvectors() * clamped.asDiagonal() * solver.eigenvectors().transpose();
}

}  // namespace

const char* toString(MbicpStatus status) {
  switch (status) {
    case MbicpStatus::kConverged:
      return "converged";
    case MbicpStatus::kMaxIterations:
      return "max_iterations";
    case MbicpStatus::kTooFewAssociations:
      return "too_few_associations";
    case MbicpStatus::kDegenerate:
      return "degenerate";
  }
  return "unknown";
}

Mbicp::Mbicp(const MbicpOptions& options) : options_(options) {}

void Mbicp::setReference(const Scan& reference) {
  ReferencePoints single;
  single.append(reference.points);
  setReference(single);
}

void Mbicp::setReference(const ReferencePoints& reference) {
  ref_points_.clear();
  ref_has_next_.clear();
  ref_normals_.clear();
  ref_tangents_.clear();
  ref_sampling_variance_.clear();
  appendScans(reference, 0);
  sortByBearing();
}

void Mbicp::extendReference(const ReferencePoints& reference, std::size_t first_new_scan) {
  if (first_new_scan == 0 || ref_points_.empty()) {
    setReference(reference);
    return;
  }
  const std::size_t old_count = ref_points_.size();
  appendScans(reference, first_new_scan);
  mergeByBearing(old_count);
}

void Mbicp::appendScans(const ReferencePoints& reference, std::size_t first_scan) {
  const std::size_t first_new = ref_points_.size();
  // Segments join neighbouring beams of one surface (never two scans, never across a missing beam).
  const std::vector<std::uint8_t> joins = joinSurfaces(
      reference, SurfaceOptions{options_.segment_max_gap, options_.segment_max_incidence}, first_scan);
  for (std::size_t scan = first_scan; scan < reference.scan_starts.size(); ++scan) {
    const Eigen::Vector2d origin = reference.scanOrigin(scan);
    const double step = angularStep(reference, scan);
    std::size_t previous = reference.points.size();  // the scan's last finite point so far
    for (std::size_t i = reference.scan_starts[scan]; i < reference.scanEnd(scan); ++i) {
      const Eigen::Vector2d& point = reference.points[i];
      if (!point.allFinite()) continue;
      if (previous + 1 == i && joins[previous]) ref_has_next_.back() = 1;
      previous = i;
      ref_points_.push_back(point);
      ref_has_next_.push_back(0);
      // The surface the beam hit lies anywhere in the beam's angular cell: uniform over range * step.
      const Eigen::Vector2d beam = point - origin;
      const double range = beam.norm();
      const bool sampled = range > 0.0;
      ref_tangents_.push_back(sampled ? Eigen::Vector2d(Eigen::Vector2d(-beam.y(), beam.x()) / range)
                                      : Eigen::Vector2d::Zero());
      ref_sampling_variance_.push_back(sampled ? range * step * range * step / 12.0 : 0.0);
    }
  }
  const std::size_t n = ref_points_.size();
  ref_normals_.resize(n, Eigen::Vector2d::Zero());
  for (std::size_t i = first_new; i < n; ++i) {
    const bool has_prev = i > 0 && ref_has_next_[i - 1];
    const bool has_next = ref_has_next_[i];
    if (has_prev && has_next) {
      ref_normals_[i] = unitNormal(ref_points_[i + 1] - ref_points_[i - 1]);
    } else if (has_next) {
      ref_normals_[i] = unitNormal(ref_points_[i + 1] - ref_points_[i]);
    } else if (has_prev) {
      ref_normals_[i] = unitNormal(ref_points_[i] - ref_points_[i - 1]);
    }
  }
}

Mbicp::WalkEntry Mbicp::walkEntry(int j) const {
  const double l_sq = options_.metric_l * options_.metric_l;
  WalkEntry entry;
  entry.point = ref_points_[j];
  entry.metric_inverse = 1.0 / (ref_points_[j].squaredNorm() + l_sq);
  entry.index = j;
  entry.has_next = ref_has_next_[j];
  entry.has_previous = j > 0 && ref_has_next_[j - 1];
  entry.to_next =
      entry.has_next ? Eigen::Vector2d(ref_points_[j + 1] - ref_points_[j]) : Eigen::Vector2d::Zero();
  entry.from_previous =
      entry.has_previous ? Eigen::Vector2d(ref_points_[j] - ref_points_[j - 1]) : Eigen::Vector2d::Zero();
  entry.range = ref_points_[j].norm();
  entry.reach = std::max(entry.to_next.norm(), entry.from_previous.norm());
  return entry;
}

void Mbicp::sortByBearing() {
  // A counting sort into n equal bearing buckets (the walk's starting points), then each small bucket by
  // bearing: linear in the points where a comparison sort is not, for the local map's thousands.
  const std::size_t n = ref_points_.size();
  const std::size_t buckets = std::max<std::size_t>(n, 1);
  const auto edge = [buckets](std::size_t b) {
    return -M_PI + 2.0 * M_PI * static_cast<double>(b) / static_cast<double>(buckets);
  };
  std::vector<double> bearing(n);
  std::vector<std::size_t> bucket(n);
  bucket_first_.assign(buckets + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    bearing[i] = fastAtan2(ref_points_[i].y(), ref_points_[i].x());
    // The bucket whose edges hold the bearing, exactly as the edges are computed.
    auto k = static_cast<std::size_t>(
        std::clamp((bearing[i] + M_PI) / (2.0 * M_PI) * buckets, 0.0, static_cast<double>(buckets)));
    while (k < buckets && edge(k + 1) <= bearing[i]) ++k;
    while (k > 0 && edge(k) > bearing[i]) --k;
    bucket[i] = k;
    ++bucket_first_[k + 1];
  }
  for (std::size_t b = 0; b < buckets; ++b) bucket_first_[b + 1] += bucket_first_[b];
  sorted_index_.resize(n);
  std::vector<int> next(bucket_first_.begin(), bucket_first_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) sorted_index_[next[bucket[i]]++] = static_cast<int>(i);
  for (std::size_t b = 0; b < buckets; ++b) {
    std::sort(sorted_index_.begin() + bucket_first_[b], sorted_index_.begin() + bucket_first_[b + 1],
              [&](int x, int y) { return bearing[x] < bearing[y] || (bearing[x] == bearing[y] && x < y); });
  }
  sorted_bearing_.resize(n);
  walk_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    sorted_bearing_[k] = bearing[sorted_index_[k]];
    walk_[k] = walkEntry(sorted_index_[k]);
  }
}

void Mbicp::mergeByBearing(std::size_t old_count) {
  // The new points sorted by (bearing, index), merged with the sorted old ones: the order a full sort of
  // all of them gives, in time linear in the old ones.
  const std::size_t n = ref_points_.size();
  std::vector<std::pair<double, int>>& added = added_scratch_;
  added.clear();
  for (std::size_t i = old_count; i < n; ++i) {
    added.emplace_back(fastAtan2(ref_points_[i].y(), ref_points_[i].x()), static_cast<int>(i));
  }
  std::sort(added.begin(), added.end());
  // Merged in place from the back: the larger bearing last; at equal bearings the new point (its index is
  // the larger) goes after the old one.
  sorted_index_.resize(n);
  sorted_bearing_.resize(n);
  walk_.resize(n);
  std::ptrdiff_t old_k = static_cast<std::ptrdiff_t>(old_count) - 1;
  for (std::ptrdiff_t b = static_cast<std::ptrdiff_t>(added.size()) - 1,
                      k = static_cast<std::ptrdiff_t>(n) - 1;
       b >= 0; --k) {
    if (old_k >= 0 && sorted_bearing_[old_k] > added[b].first) {
      sorted_index_[k] = sorted_index_[old_k];
      sorted_bearing_[k] = sorted_bearing_[old_k];
      walk_[k] = walk_[old_k];
      --old_k;
    } else {
      sorted_index_[k] = added[b].second;
      sorted_bearing_[k] = added[b].first;
      walk_[k] = walkEntry(added[b].second);
      --b;
    }
  }
  // Each of the n equal buckets starts at the first point at or past its lower edge.
  const std::size_t buckets = std::max<std::size_t>(n, 1);
  bucket_first_.assign(buckets + 1, static_cast<int>(n));
  std::size_t k = 0;
  for (std::size_t bucket = 0; bucket <= buckets; ++bucket) {
    const double edge = -M_PI + 2.0 * M_PI * static_cast<double>(bucket) / static_cast<double>(buckets);
    while (k < n && sorted_bearing_[k] < edge) ++k;
    bucket_first_[bucket] = static_cast<int>(bucket == buckets ? n : k);
  }
}

inline void Mbicp::considerPoint(const Eigen::Vector2d& p, const WalkEntry& entry,
                                 Candidate* candidate) const {
  // dapSquared() with the point's 1 / (|q|^2 + L^2) precomputed.
  const Eigen::Vector2d d = p - entry.point;
  const double cross = d.x() * entry.point.y() - d.y() * entry.point.x();
  const double d_sq = d.squaredNorm() - cross * cross * entry.metric_inverse;
  if (d_sq < candidate->best) {
    candidate->best = d_sq;
    candidate->element = entry.index;
    candidate->segment = false;
    candidate->target = entry.point;
  }
}

inline void Mbicp::considerSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                                   const Eigen::Vector2d& e, int j, double l_sq, double u_scale,
                                   Candidate* candidate) const {
  // Closest point of segment q -> q + e (reference segment j) under the metric, with the metric frozen at
  // p (it varies slowly): minimise (a - t e)^T M (a - t e), M = I - u u^T / (|p|^2 + L^2), u = (p_y, -p_x).
  const Eigen::Vector2d u(p.y(), -p.x());
  const Eigen::Vector2d a = p - q;
  const double ue = u.dot(e), ua = u.dot(a);
  const double eme = e.squaredNorm() - ue * ue * u_scale;
  if (!(eme > 0.0)) return;
  const double along = e.dot(a) - ue * ua * u_scale;
  if (along <= 0.0 || along >= eme) return;  // the end points are candidates of their own
  const Eigen::Vector2d on_segment = q + (along / eme) * e;
  const double d_sq = dapSquared(p, on_segment, l_sq);
  if (d_sq < candidate->best) {
    candidate->best = d_sq;
    candidate->element = j;
    candidate->segment = true;
    candidate->target = on_segment;
  }
}

inline void Mbicp::considerEntry(const Eigen::Vector2d& p, const WalkEntry& entry, double l_sq,
                                 double u_scale, Candidate* candidate) const {
  considerPoint(p, entry, candidate);
  // Both segments of the point; a segment met again from its other end point cannot change the best.
  if (entry.has_next) considerSegment(p, entry.point, entry.to_next, entry.index, l_sq, u_scale, candidate);
  if (entry.has_previous) {
    considerSegment(p, entry.point - entry.from_previous, entry.from_previous, entry.index - 1, l_sq, u_scale,
                    candidate);
  }
}

Mbicp::Association Mbicp::associationOf(const Eigen::Vector2d& p, const Candidate& candidate) const {
  const int j = candidate.element;
  Association association;
  association.point = p;
  association.target = candidate.target;
  association.on_segment = candidate.segment;
  association.distance_sq = std::max(0.0, candidate.best);
  association.weight = 1.0;
  const bool isolated = !candidate.segment && ref_normals_[j].isZero();
  association.normal = candidate.segment ? unitNormal(ref_points_[j + 1] - ref_points_[j]) : ref_normals_[j];
  association.sampling_tangent = isolated ? ref_tangents_[j] : Eigen::Vector2d::Zero();
  association.sampling_variance = isolated ? ref_sampling_variance_[j] : 0.0;
  return association;
}

int Mbicp::walkStart(double bearing) const {
  // std::lower_bound() of the bearing, from its bucket's first point (a step or two, not a search).
  const int n = static_cast<int>(sorted_bearing_.size());
  const int buckets = static_cast<int>(bucket_first_.size()) - 1;
  if (!(buckets > 0) || !(bearing == bearing)) {
    return static_cast<int>(std::lower_bound(sorted_bearing_.begin(), sorted_bearing_.end(), bearing) -
                            sorted_bearing_.begin());
  }
  const double position = (bearing + M_PI) * (buckets / (2.0 * M_PI));
  int k = bucket_first_[std::clamp(static_cast<int>(position), 0, buckets - 1)];
  while (k > 0 && sorted_bearing_[k - 1] >= bearing) --k;
  while (k < n && sorted_bearing_[k] < bearing) ++k;
  return k;
}

void Mbicp::associatePoint(const Eigen::Vector2d& p, double gate_sq, int warm_entry, Candidate* candidate) {
  const double l_sq = options_.metric_l * options_.metric_l;
  const double window = std::min(options_.bearing_window, M_PI);
  const double u_scale = 1.0 / (p.squaredNorm() + l_sq);
  double& best = candidate->best;
  best = gate_sq;
  const int n = static_cast<int>(sorted_bearing_.size());
  // The entry of the last iteration first: the estimate moved little since, so it sets a tight best and
  // the walk below stops within a few points.
  if (warm_entry >= 0 && warm_entry < n) considerEntry(p, walk_[warm_entry], l_sq, u_scale, candidate);
  // Walk outward in bearing from p's own bearing, both ways, within the window (wrapping at +-pi for
  // 360-degree scans). A reference point at bearing offset D is at least |p| sin D away from p, and
  // d_ap^2 >= |d|^2 L^2 / ((|p| + |d|)^2 + L^2), which grows with |d|: once that bound exceeds the
  // best candidate so far, nothing farther in bearing can win, and the walk stops. Bearings are
  // approximations (fastAtan2): the reach is widened by twice their error.
  const double bearing = fastAtan2(p.y(), p.x());
  const double range = p.norm();
  const int start = walkStart(bearing);
  double reach = window;
  double reach_best = -1.0;
  double d_min = HUGE_VAL;  // no element farther than this from p can win
  auto update_reach = [&]() {
    // Smallest |d| whose bound reaches `best`: root of d^2 (L^2 - best) - 2 best |p| d - best (|p|^2 + L^2).
    reach_best = best;
    const double denominator = l_sq - best;
    if (!(denominator > 0.0) || !(range > 0.0)) {
      reach = window;
      d_min = HUGE_VAL;
      return;
    }
    d_min = (best * range +
             std::sqrt(best * best * range * range + denominator * best * (range * range + l_sq))) /
            denominator;
    if (d_min >= range) {
      reach = window;
      return;
    }
    // asin(s) <= tan(asin(s)) = s / sqrt(1 - s^2): a slightly wider, still valid reach without asin.
    const double sine = d_min / range;
    reach = std::min(window, sine / std::sqrt(1.0 - sine * sine) + 2.0 * kFastAtan2Error);
  };
  int best_entry = -1;
  auto visit = [&](int k) {
    // An entry whose point and segments all lie farther from p than d_min in range alone cannot win.
    const WalkEntry& entry = walk_[k];
    if (std::abs(entry.range - range) > d_min + entry.reach) return;
    const int before = candidate->element;
    const bool before_segment = candidate->segment;
    considerEntry(p, entry, l_sq, u_scale, candidate);
    if (candidate->element != before || candidate->segment != before_segment) best_entry = k;
    // The reach from a larger `best` is still a valid (looser) bound: refresh only on a real gain.
    if (best < 0.5 * reach_best) update_reach();
  };
  if (candidate->element >= 0) best_entry = warm_entry;
  update_reach();
  for (int step = 0; step < n; ++step) {  // counter-clockwise
    int k = start + step;
    double offset = (k >= n ? sorted_bearing_[k -= n] + 2.0 * M_PI : sorted_bearing_[k]) - bearing;
    if (offset > reach) break;
    visit(k);
  }
  for (int step = 1; step < n; ++step) {  // clockwise
    int k = start - step;
    double offset = bearing - (k < 0 ? sorted_bearing_[k += n] - 2.0 * M_PI : sorted_bearing_[k]);
    if (offset > reach) break;
    visit(k);
  }
  candidate->entry = best_entry;
}

void Mbicp::associate(const std::vector<Eigen::Vector2d>& moved, double gate, std::vector<Association>* out) {
  out->clear();
  warm_entry_.resize(moved.size(), -1);
  for (std::size_t i = 0; i < moved.size(); ++i) {
    Candidate candidate;
    associatePoint(moved[i], gate * gate, warm_entry_[i], &candidate);
    warm_entry_[i] = candidate.entry;
    if (candidate.element >= 0) out->push_back(associationOf(moved[i], candidate));
  }
}

bool Mbicp::converged(const Eigen::Vector3d& step, const Pose2D& pose, double error,
                      Progress* progress) const {
  const auto within_min_step = [&](const Pose2D& delta) {
    return std::abs(delta.x) < options_.min_step_xy && std::abs(delta.y) < options_.min_step_xy &&
           std::abs(delta.theta) < options_.min_step_theta;
  };
  const bool small_step = within_min_step(Pose2D(step.x(), step.y(), step.z()));
  const bool no_progress =
      progress->previous_error >= 0.0 &&
      std::abs(progress->previous_error - error) <= options_.error_ratio * std::max(error, 1e-12);
  // Back where it was two iterations ago: the associations flip between two sets (a point at the gate's
  // edge, or between an end point's line and a neighbouring segment) and neither step makes progress.
  const bool cycling =
      progress->settled_poses >= 2 && within_min_step(pose * progress->two_poses_ago.inverse());
  progress->two_poses_ago = progress->previous_pose;
  progress->previous_pose = pose;
  ++progress->settled_poses;
  progress->quiet_iterations = (small_step || no_progress || cycling) ? progress->quiet_iterations + 1 : 0;
  progress->previous_error = error;
  return progress->quiet_iterations >= options_.converged_iterations;
}

MbicpResult Mbicp::match(const Scan& scan, const Pose2D& initial, const PosePrior* prior) {
  MbicpResult result;
  result.pose = initial.isFinite() ? initial : Pose2D();
  result.covariance = Eigen::Matrix3d::Identity() * kMaxVariance;
  if (prior && !(prior->mean.isFinite() && prior->information.allFinite())) prior = nullptr;

  std::vector<Eigen::Vector2d>& points = points_;
  points.clear();
  for (const auto& p : scan.points) {
    if (p.allFinite()) points.push_back(p);
  }
  const std::size_t min_associations = std::max<std::size_t>(
      3, static_cast<std::size_t>(std::ceil(options_.min_association_ratio * points.size())));
  if (ref_points_.empty() || points.size() < 3) {
    result.status = MbicpStatus::kTooFewAssociations;
    return result;
  }

  Progress progress;
  const double fine_gate =
      options_.fine_max_distance > 0.0 ? options_.fine_max_distance : options_.max_distance;
  bool settled = fine_gate == options_.max_distance;
  result.status = MbicpStatus::kMaxIterations;
  moved_.resize(points.size());
  warm_entry_.assign(points.size(), -1);

  for (int iteration = 1; iteration <= options_.max_iterations; ++iteration) {
    result.iterations = iteration;
    const double c = std::cos(result.pose.theta), s = std::sin(result.pose.theta);
    for (std::size_t i = 0; i < points.size(); ++i) {
      moved_[i] = Eigen::Vector2d(c * points[i].x() - s * points[i].y() + result.pose.x,
                                  s * points[i].x() + c * points[i].y() + result.pose.y);
    }
    associate(moved_, settled ? fine_gate : options_.max_distance, &associations_);
    if (associations_.size() < min_associations) {
      result.status = MbicpStatus::kTooFewAssociations;
      result.associations = static_cast<int>(associations_.size());
      return result;
    }
    Eigen::Vector3d step, scan_only_step;
    double error = 0.0;
    const bool solved =
        solveStep(result.pose, settled, min_associations, prior, &step, &scan_only_step, &error);
    if (scan_only_step.allFinite()) {
      result.scan_only_pose =
          Pose2D(scan_only_step.x(), scan_only_step.y(), scan_only_step.z()) * result.pose;
    }
    result.associations = static_cast<int>(associations_.size());
    result.rms_error = std::sqrt(error);
    if (!solved) {
      result.status = MbicpStatus::kDegenerate;
      break;
    }
    result.pose = Pose2D(step.x(), step.y(), step.z()) * result.pose;

    if (!settled) {
      // Wide gate until the estimate settles; convergence is only judged under the fine gate.
      settled = std::abs(step.x()) < options_.settle_step_xy &&
                std::abs(step.y()) < options_.settle_step_xy &&
                std::abs(step.z()) < options_.settle_step_theta;
      progress.previous_error = -1.0;
      continue;
    }
    if (converged(step, result.pose, error, &progress)) {
      result.status = MbicpStatus::kConverged;
      break;
    }
  }

  if (!prior) result.scan_only_pose = result.pose;
  estimateUncertainty(prior, &result);
  if (!result.pose.isFinite()) {
    result.pose = initial.isFinite() ? initial : Pose2D();
    result.status = MbicpStatus::kDegenerate;
  }
  return result;
}

double Mbicp::informationScale(double constraints) const {
  if (!(options_.independent_points > 0.0) || !(constraints > 0.0)) return 1.0;
  return std::min(1.0, options_.independent_points / constraints);
}

double Mbicp::robustScaleSq() {
  if (!(options_.robust_scale > 0.0) || associations_.empty()) return 0.0;
  std::vector<double>& distance_sq = distance_sq_;
  distance_sq.resize(associations_.size());
  for (std::size_t i = 0; i < distance_sq.size(); ++i) distance_sq[i] = associations_[i].distance_sq;
  auto median = distance_sq.begin() + distance_sq.size() / 2;
  std::nth_element(distance_sq.begin(), median, distance_sq.end());
  const double noise_sq = options_.point_noise * options_.point_noise;
  return options_.robust_scale * options_.robust_scale * std::max({*median, noise_sq, kNoiseFloor});
}

Eigen::Matrix2d Mbicp::associationMetric(const Association& assoc, bool settled, double l_sq,
                                         double* residual_sq) const {
  const Eigen::Vector2d& p = assoc.point;
  const Eigen::Vector2d& c = assoc.target;
  const Eigen::Vector2d u(c.y(), -c.x());
  Eigen::Matrix2d m = Eigen::Matrix2d::Identity() - u * u.transpose() / (c.squaredNorm() + l_sq);
  // A point just past a segment's end point: point-to-point while the estimate moves (its pull along
  // the surface helps turn a scan in from afar), then onto that end point's line (point-to-point would
  // pull it towards the last reference beam: a rotation bias at every edge).
  const bool line_residual =
      options_.point_to_line && (assoc.on_segment || (settled && !assoc.normal.isZero()));
  *residual_sq = assoc.distance_sq;
  if (line_residual) {
    // Distance to the line under the metric: remove the metric-weighted tangent direction.
    const Eigen::Vector2d tangent(assoc.normal.y(), -assoc.normal.x());
    const Eigen::Vector2d m_tangent = m * tangent;
    m -= m_tangent * m_tangent.transpose() / tangent.dot(m_tangent);
    const double r = assoc.normal.dot(p - c);
    *residual_sq = r * r;
  } else if (options_.point_noise > 0.0 && assoc.sampling_variance > 0.0) {
    // Isolated reference point: across its beam the residual is mostly the sampling's, not the pose's.
    const double noise_sq = options_.point_noise * options_.point_noise;
    const double keep = noise_sq / (noise_sq + assoc.sampling_variance);
    const Eigen::Vector2d m_tangent = m * assoc.sampling_tangent;
    m -= (1.0 - keep) * m_tangent * m_tangent.transpose() / assoc.sampling_tangent.dot(m_tangent);
    const Eigen::Vector2d d = p - c;
    *residual_sq = d.dot(m * d);
  }
  return m;
}

bool Mbicp::solveStep(const Pose2D& pose, bool settled, std::size_t min_associations, const PosePrior* prior,
                      Eigen::Vector3d* step, Eigen::Vector3d* scan_only_step, double* error) {
  // Trimming: the worst associations (moved objects, unmatched structure) do not vote; robust weights make
  // the rest fade smoothly with their distance.
  const std::size_t keep = std::max(
      min_associations, static_cast<std::size_t>(std::ceil(options_.trim_fraction * associations_.size())));
  if (keep < associations_.size()) {
    std::nth_element(
        associations_.begin(), associations_.begin() + keep, associations_.end(),
        [](const Association& a, const Association& b) { return a.distance_sq < b.distance_sq; });
    associations_.resize(keep);
  }
  const double robust_scale_sq = robustScaleSq();
  // Closed-form step: minimise sum (r + J q)^T M (r + J q) over the increment q = (x, y, theta), with
  // the point moved by the linearised rotation (J = [1 0 -p_y; 0 1 p_x]) and M the d_ap metric at the target.
  const double l_sq = options_.metric_l * options_.metric_l;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double error_sum = 0.0, residual_sq = 0.0, weight_sum = 0.0;
  for (auto& assoc : associations_) {
    const Eigen::Vector2d& p = assoc.point;
    const Eigen::Vector2d& c = assoc.target;
    double residual_sq_one = 0.0;
    Eigen::Matrix2d m = associationMetric(assoc, settled, l_sq, &residual_sq_one);
    assoc.weight = robust_scale_sq > 0.0 ? 1.0 / (1.0 + assoc.distance_sq / robust_scale_sq) : 1.0;
    m *= assoc.weight;
    residual_sq += assoc.weight * residual_sq_one;
    weight_sum += assoc.weight;
    error_sum += assoc.weight * assoc.distance_sq;
    Eigen::Matrix<double, 2, 3> jacobian;
    jacobian << 1.0, 0.0, -p.y(), 0.0, 1.0, p.x();
    const Eigen::Matrix<double, 3, 2> jt_m = jacobian.transpose() * m;
    a += jt_m * jacobian;
    b += jt_m * (p - c);
  }
  // The weights' sum is the number of associations that count (all of them without robust weights).
  const double count = weight_sum;
  *error = error_sum / std::max(count, kNoiseFloor);
  // A whisker of damping keeps directions nothing constrains (a straight wall) at zero step.
  const auto damped = [](Eigen::Matrix3d m) {
    m.diagonal() += Eigen::Vector3d::Constant(1e-9 * m.trace() + 1e-12);
    return m;
  };
  *scan_only_step = damped(a).ldlt().solve(-b);
  // The scan's information: the same normal equations in units of the residuals' (calibrated) noise.
  const double variance = std::max(residual_sq / std::max(1.0, count - 3.0), kNoiseFloor);
  scan_information_ = a * (informationScale(count) / variance);
  if (prior) {
    // MAP step: the scan's information plus the prior on the pose. The pose moves by G q for an increment
    // q applied in the reference frame.
    const double weight = informationScale(count) / variance;
    a *= weight;
    b *= weight;
    const Eigen::Matrix3d g = incrementToPose(pose);
    if (scan_noise_scale_ != ScanNoiseScale::Ones()) {
      // The noise scale divides the information along its directions in the pose's own coordinates
      // (I = F^T a F, F = G^-1); the same map on a and b keeps the scan's own minimum.
      const Eigen::Matrix3d f = g.inverse();
      const InformationDirections directions = informationDirections(f.transpose() * a * f);
      const Eigen::Matrix3d map =
          g.transpose() * scaledInformationMap(directions, scan_noise_scale_) * f.transpose();
      a = map * a;
      a = 0.5 * (a + a.transpose());
      b = map * b;
    }
    const Eigen::Vector3d offset(pose.x - prior->mean.x, pose.y - prior->mean.y,
                                 normalizeAngle(pose.theta - prior->mean.theta));
    a += g.transpose() * prior->information * g;
    b += g.transpose() * prior->information * offset;
  }
  *step = prior ? damped(a).ldlt().solve(-b) : *scan_only_step;
  return step->allFinite();
}

void Mbicp::estimateUncertainty(const PosePrior* prior, MbicpResult* result) const {
  // Uncertainty from point-to-line information: only the component of each residual along the reference
  // normal is informative (a point may slide along a wall), so a corridor shows its unconstrained axis.
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  double residual_sq = 0.0, constraints = 0.0;
  int surface_points = 0;
  for (const auto& assoc : associations_) {
    if (assoc.normal.isZero()) continue;
    const Eigen::Vector2d& p = assoc.point;  // in the reference frame, as the increments are
    const Eigen::Vector3d row(assoc.normal.x(), assoc.normal.y(),
                              assoc.normal.y() * p.x() - assoc.normal.x() * p.y());
    information += assoc.weight * row * row.transpose();
    const double r = assoc.normal.dot(assoc.point - assoc.target);
    residual_sq += assoc.weight * r * r;
    constraints += assoc.weight;
    ++surface_points;
  }
  if (surface_points <= 3 || !(constraints > 3.0)) {
    if (!prior) {
      result->status = MbicpStatus::kTooFewAssociations;
      return;
    }
    result->degenerate = true;
    result->covariance = clampEigenvalues(prior->information.inverse(), kMinVariance, kMaxVariance);
    return;
  }
  // Noise floor of 1 cm: residuals of a noise-free or perfectly interleaved pair are not zero-uncertainty.
  const double variance =
      std::max(residual_sq / (constraints - 3), kNoiseFloor) / informationScale(constraints);
  // Degeneracy test in consistent units: scale the rotation by the mean point radius.
  double radius = 0.0;
  for (const auto& assoc : associations_) radius += assoc.point.norm();
  radius = std::max(radius / associations_.size(), 1e-3);
  Eigen::Matrix3d scaled = information;
  scaled.row(2) /= radius;
  scaled.col(2) /= radius;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scaled);
  const Eigen::Vector3d eigenvalues = solver.eigenvalues();
  const double threshold = options_.degenerate_eigenvalue * eigenvalues.maxCoeff();
  result->degenerate = !(eigenvalues.minCoeff() > threshold);

  // The information is of an increment applied in the reference frame (pose = delta * estimate);
  // G maps that increment to the pose's own (x, y, theta).
  const Eigen::Matrix3d to_pose = incrementToPose(result->pose);
  const Eigen::Matrix3d from_pose = to_pose.inverse();
  // What the MAP weighed the scan with (the metric's normal equations of the last iteration): a posterior
  // built from it below is the one the iterations converged to.
  const Eigen::Matrix3d stated = from_pose.transpose() * scan_information_ * from_pose;
  result->scan_directions = informationDirections(stated);
  result->scan_information = scaledInformationMap(result->scan_directions, scan_noise_scale_) * stated;
  result->scan_information = 0.5 * (result->scan_information + result->scan_information.transpose());
  if (prior) {
    const Eigen::Matrix3d posterior = result->scan_information + prior->information;
    result->covariance = clampEigenvalues(posterior.inverse(), kMinVariance, kMaxVariance);
  } else if (result->degenerate) {
    result->status = MbicpStatus::kDegenerate;
    // Pseudo-inverse of the scaled information: the unconstrained direction gets the maximum variance.
    Eigen::Vector3d inverse_eigen;
    for (int i = 0; i < 3; ++i) {
      inverse_eigen[i] = eigenvalues[i] > threshold ? variance / eigenvalues[i] : kMaxVariance;
    }
    Eigen::Matrix3d cov_scaled =
        solver.eigenvectors() * inverse_eigen.asDiagonal() * solver.eigenvectors().transpose();
    cov_scaled.row(2) /= radius;
    cov_scaled.col(2) /= radius;
    result->covariance =
        clampEigenvalues(to_pose * cov_scaled * to_pose.transpose(), kMinVariance, kMaxVariance);
  } else {
    result->covariance = clampEigenvalues(to_pose * (variance * information.inverse()) * to_pose.transpose(),
                                          kMinVariance, kMaxVariance);
  }
}

}  // namespace hglasm
