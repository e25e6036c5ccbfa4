// The Kümmerle et al. 2009 relations metric.
#include "hglasm_odometry/evaluation/relations.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numeric>
#include <sstream>

#include "hglasm_odometry/evaluation/statistics.h"

namespace hglasm {

namespace {

/// The first pose of `trajectory` (sorted by stamp) stamped at or after `stamp`.
std::vector<StampedPose>::const_iterator firstAtOrAfter(const std::vector<StampedPose>& trajectory,
                                                        double stamp) {
  return std::lower_bound(trajectory.begin(), trajectory.end(), stamp,
                          [](const StampedPose& pose, double value) { return pose.stamp < value; });
}

/// Whether a relation spans at most `max_span` seconds (<= 0: any span).
bool withinSpan(const Relation& relation, double max_span) {
  return !(max_span > 0.0 && std::abs(relation.t2 - relation.t1) > max_span);
}

/// Whether the k-th of per-relation estimates exists and is valid.
template <typename Estimate>
bool validAt(const std::vector<Estimate>& estimates, const std::vector<bool>& valid, std::size_t k) {
  return k < estimates.size() && k < valid.size() && valid[k];
}

/// The heading of `trajectory` (sorted by stamp) at `stamp`, interpolated between the samples around it.
bool headingAt(const std::vector<StampedPose>& trajectory, double stamp, double* heading) {
  const auto after = firstAtOrAfter(trajectory, stamp);
  if (after == trajectory.begin() || after == trajectory.end()) return false;
  const StampedPose& a = *std::prev(after);
  const StampedPose& b = *after;
  const double fraction = b.stamp > a.stamp ? (stamp - a.stamp) / (b.stamp - a.stamp) : 0.0;
  *heading = a.pose.theta + fraction * normalizeAngle(b.pose.theta - a.pose.theta);
  return true;
}

/// The ratio of the sums and its standard error: the residuals of the relations about the scale times
/// their distances, as a ratio estimator's (n / (n - 1) for the scale fitted; none from one relation).
void setAlongTrackScale(const std::vector<double>& along, const std::vector<double>& distances,
                        RelationStats* stats) {
  const double total = std::accumulate(distances.begin(), distances.end(), 0.0);
  if (!(total > 0.0)) return;
  const double scale = std::accumulate(along.begin(), along.end(), 0.0) / total;
  double scatter = 0.0;
  for (std::size_t i = 0; i < along.size(); ++i) {
    const double residual = along[i] - scale * distances[i];
    scatter += residual * residual;
  }
  const double n = static_cast<double>(along.size());
  stats->along_track_scale = scale;
  stats->along_track_scale_error = n > 1.0 ? std::sqrt(scatter * n / (n - 1.0)) / total : 0.0;
  stats->along_track_count = static_cast<int>(along.size());
}

}  // namespace

long findStamp(const std::vector<StampedPose>& trajectory, double stamp, double tolerance) {
  const auto after = firstAtOrAfter(trajectory, stamp);
  long best = -1;
  double best_gap = tolerance;
  // The nearest stamp is either the first one at or after `stamp` or the one just before it.
  for (auto it : {after, after == trajectory.begin() ? trajectory.end() : std::prev(after)}) {
    if (it == trajectory.end()) continue;
    const double gap = std::abs(it->stamp - stamp);
    if (gap <= best_gap) {
      best_gap = gap;
      best = static_cast<long>(it - trajectory.begin());
    }
  }
  return best;
}

bool readRelations(const std::string& path, std::vector<Relation>* relations, std::string* error) {
  std::ifstream file(path);
  if (!file) {
    if (error) *error = "cannot open relations file '" + path + "'";
    return false;
  }
  relations->clear();
  std::string line;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;  // blank line or comment
    std::istringstream fields(line);
    double t1, t2, x, y, z, roll, pitch, yaw;
    if (!(fields >> t1 >> t2 >> x >> y >> z >> roll >> pitch >> yaw) || !std::isfinite(t1) ||
        !std::isfinite(t2) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw)) {
      if (error) {
        *error = path + ":" + std::to_string(line_number) + ": expected 't1 t2 x y z roll pitch yaw', got '" +
                 line + "'";
      }
      return false;
    }
    Relation relation;
    relation.t1 = t1;
    relation.t2 = t2;
    relation.motion = Pose2D(x, y, yaw);
    relations->push_back(relation);
  }
  return true;
}

RelationStats evaluateRelations(const std::vector<Relation>& relations,
                                const std::vector<StampedPose>& trajectory, double max_span,
                                double stamp_tolerance) {
  std::vector<Pose2D> estimated;
  std::vector<bool> valid;
  relativeMotions(relations, trajectory, &estimated, &valid, stamp_tolerance);
  return evaluateRelativeMotions(relations, estimated, valid, max_span);
}

RelationStats evaluateRelativeMotions(const std::vector<Relation>& relations,
                                      const std::vector<Pose2D>& estimated, const std::vector<bool>& valid,
                                      double max_span) {
  RelationStats stats;
  std::vector<double> trans_errors, rot_errors_deg, along, reference_distances;
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const Relation& relation = relations[k];
    if (!withinSpan(relation, max_span)) continue;
    if (!validAt(estimated, valid, k)) {
      ++stats.missing;
      continue;
    }
    // Kümmerle's estimated ⊖ reference: the residual motion left once the reference is undone.
    const Pose2D residual = relativePose(relation.motion, estimated[k]);
    const double distance = relation.motion.translationNorm();
    if (distance >= RelationStats::kScaleMinDistance) {
      along.push_back((estimated[k].x * relation.motion.x + estimated[k].y * relation.motion.y) / distance);
      reference_distances.push_back(distance);
    }
    trans_errors.push_back(residual.translationNorm());
    rot_errors_deg.push_back(std::abs(normalizeAngle(residual.theta)) * kRadToDeg);
  }
  stats.count = static_cast<int>(trans_errors.size());
  if (stats.count == 0) return stats;
  setAlongTrackScale(along, reference_distances, &stats);
  // Two passes (mean, then spread) so tiny spreads are not lost to cancellation.
  const auto moments = [](const std::vector<double>& values, double* mean, double* std_dev, double* sq_mean) {
    double sum = 0.0, sq_sum = 0.0;
    for (double value : values) {
      sum += value;
      sq_sum += value * value;
    }
    const double n = static_cast<double>(values.size());
    *mean = sum / n;
    *sq_mean = sq_sum / n;
    double spread = 0.0;
    for (double value : values) spread += (value - *mean) * (value - *mean);
    *std_dev = std::sqrt(spread / n);  // population standard deviation
  };
  moments(trans_errors, &stats.trans_mean, &stats.trans_std, &stats.trans_sq_mean);
  moments(rot_errors_deg, &stats.rot_mean_deg, &stats.rot_std_deg, &stats.rot_sq_mean_deg);
  stats.trans_median = median(trans_errors);
  stats.rot_median_deg = median(rot_errors_deg);
  return stats;
}

void relativeMotions(const std::vector<Relation>& relations, const std::vector<StampedPose>& trajectory,
                     std::vector<Pose2D>* estimated, std::vector<bool>* valid, double stamp_tolerance) {
  estimated->assign(relations.size(), Pose2D());
  valid->assign(relations.size(), false);
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const long i1 = findStamp(trajectory, relations[k].t1, stamp_tolerance);
    const long i2 = findStamp(trajectory, relations[k].t2, stamp_tolerance);
    if (i1 < 0 || i2 < 0) continue;
    (*estimated)[k] = relativePose(trajectory[i1].pose, trajectory[i2].pose);
    (*valid)[k] = true;
  }
}

TimingFit fitTimingOffset(const std::vector<Relation>& relations, const std::vector<Pose2D>& estimated,
                          const std::vector<bool>& valid, const std::vector<StampedPose>& turn_rates,
                          double max_span) {
  const double h = TimingFit::kTurnRateHalfWindow;
  const auto turn_rate = [&](double stamp, double* rate) {
    double before = 0.0, after = 0.0;
    if (!headingAt(turn_rates, stamp - h, &before) || !headingAt(turn_rates, stamp + h, &after)) return false;
    *rate = normalizeAngle(after - before) / (2.0 * h);
    return true;
  };
  std::vector<Eigen::Vector2d> regressors;  // change of turn rate, reference's turn
  std::vector<double> errors;
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const Relation& relation = relations[k];
    if (!validAt(estimated, valid, k) || !withinSpan(relation, max_span)) continue;
    double rate1 = 0.0, rate2 = 0.0;
    if (!turn_rate(relation.t1, &rate1) || !turn_rate(relation.t2, &rate2)) continue;
    const double error = normalizeAngle(estimated[k].theta - relation.motion.theta);
    if (!(std::abs(error) <= TimingFit::kMaxHeadingError)) continue;
    regressors.emplace_back(rate2 - rate1, relation.motion.theta);
    errors.push_back(error);
  }
  TimingFit fit;
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d projection = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < errors.size(); ++i) {
    normal += regressors[i] * regressors[i].transpose();
    projection += regressors[i] * errors[i];
  }
  fit.count = static_cast<int>(errors.size());
  // Without turns (or without changes of turn rate) the two cannot be told apart: nothing is fitted. (A
  // zero diagonal makes the determinant zero too.)
  if (fit.count < 3 || !(normal.determinant() > 1e-12 * normal(0, 0) * normal(1, 1))) return fit;
  const Eigen::Matrix2d inverse = normal.inverse();
  const Eigen::Vector2d estimate = inverse * projection;
  fit.offset = estimate(0);
  fit.turn_scale = estimate(1);
  double residual_sq = 0.0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const double residual = errors[i] - regressors[i].dot(estimate);
    residual_sq += residual * residual;
  }
  const double variance = residual_sq / (fit.count - 2);
  fit.offset_sd = std::sqrt(variance * inverse(0, 0));
  fit.turn_scale_sd = std::sqrt(variance * inverse(1, 1));
  fit.rate_change = std::sqrt(normal(0, 0) / fit.count);
  return fit;
}

std::vector<bool> contradictedRelations(const std::vector<Relation>& relations,
                                        const std::vector<Pose2D>& direct,
                                        const std::vector<bool>& direct_valid,
                                        const std::vector<Pose2D>& witness,
                                        const std::vector<bool>& witness_valid, double max_span,
                                        double min_disagreement, double max_agreement) {
  std::vector<bool> contradicted(relations.size(), false);
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const Relation& relation = relations[k];
    if (!withinSpan(relation, max_span)) continue;
    if (!validAt(direct, direct_valid, k) || !validAt(witness, witness_valid, k)) continue;
    const double from_reference = std::abs(normalizeAngle(direct[k].theta - relation.motion.theta));
    const double from_witness = std::abs(normalizeAngle(direct[k].theta - witness[k].theta));
    contradicted[k] = from_reference > min_disagreement && from_witness <= max_agreement;
  }
  return contradicted;
}

std::vector<RelationError> relationErrors(const std::vector<Relation>& relations,
                                          const std::vector<StampedPose>& trajectory, double max_span,
                                          double stamp_tolerance) {
  std::vector<RelationError> errors;
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const Relation& relation = relations[k];
    if (!withinSpan(relation, max_span)) continue;
    const long i1 = findStamp(trajectory, relation.t1, stamp_tolerance);
    const long i2 = findStamp(trajectory, relation.t2, stamp_tolerance);
    if (i1 < 0 || i2 < 0) continue;
    const Pose2D residual =
        relativePose(relation.motion, relativePose(trajectory[i1].pose, trajectory[i2].pose));
    errors.push_back({k, residual});
  }
  return errors;
}

CalibrationStats evaluateCalibration(const std::vector<Relation>& relations,
                                     const std::vector<StampedPose>& trajectory,
                                     const std::vector<Eigen::Matrix3d>& increment_covariances,
                                     double max_span, double stamp_tolerance) {
  CalibrationStats stats;
  if (increment_covariances.size() != trajectory.size()) return stats;
  std::vector<double> distances;
  for (const Relation& relation : relations) {
    if (!withinSpan(relation, max_span)) continue;
    const long i1 = findStamp(trajectory, relation.t1, stamp_tolerance);
    const long i2 = findStamp(trajectory, relation.t2, stamp_tolerance);
    if (i1 < 0 || i2 <= i1) continue;
    Pose2D motion;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (long i = i1 + 1; i <= i2; ++i) {
      const Pose2D step = relativePose(trajectory[i - 1].pose, trajectory[i].pose);
      covariance = composeCovariance(motion, covariance, step, increment_covariances[i]);
      motion = motion * step;
    }
    const Eigen::Vector3d error(motion.x - relation.motion.x, motion.y - relation.motion.y,
                                normalizeAngle(motion.theta - relation.motion.theta));
    const Eigen::Matrix3d regularised = covariance + Eigen::Matrix3d::Identity() * 1e-12;
    const double distance = error.dot(regularised.ldlt().solve(error));
    if (std::isfinite(distance)) distances.push_back(distance);
  }
  stats.count = static_cast<int>(distances.size());
  if (distances.empty()) return stats;
  double sum = 0.0;
  int within = 0;
  for (double distance : distances) {
    sum += distance;
    within += distance <= 7.81;
  }
  stats.mean_sq_mahalanobis = sum / distances.size();
  stats.fraction_within_3dof_95 = static_cast<double>(within) / distances.size();
  stats.median_sq_mahalanobis = kthSmallest(distances, distances.size() / 2);  // the upper median
  return stats;
}

}  // namespace hglasm
