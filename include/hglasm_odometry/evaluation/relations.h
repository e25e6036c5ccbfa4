// The Kümmerle et al. 2009 relations metric: errors of estimated relative motions against reference ones.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

/// The metric reports rotations in degrees.
inline constexpr double kRadToDeg = 180.0 / M_PI;

/// Pose of the robot at t2 expressed in the robot frame at t1.
struct Relation {
  double t1 = 0.0;
  double t2 = 0.0;
  Pose2D motion;
};

/// Reads `t1 t2 x y z roll pitch yaw` lines (z, roll, pitch ignored). False with *error on failure.
bool readRelations(const std::string& path, std::vector<Relation>* relations, std::string* error);

struct RelationStats {
  int count = 0;            ///< relations evaluated
  int missing = 0;          ///< relations whose stamps are not in the trajectory
  double trans_mean = 0.0;  ///< metres
  double trans_std = 0.0;
  double rot_mean_deg = 0.0;  ///< absolute rotational error, degrees
  double rot_std_deg = 0.0;
  double trans_sq_mean = 0.0;    ///< m^2
  double rot_sq_mean_deg = 0.0;  ///< deg^2
  double trans_median = 0.0;     ///< metres: what a typical relation sees (a few leaps move the mean)
  double rot_median_deg = 0.0;
  /// The distance travelled along the track as estimated against the reference's: over the relations that
  /// move at least kScaleMinDistance, the estimated translations projected on the reference's directions,
  /// summed, over the reference distances summed. 1 is unbiased; below 1 the estimate falls short (a scan
  /// that prefers "no motion" along a featureless corridor), above it overshoots. 0 without such relations.
  double along_track_scale = 0.0;
  /// Its standard error (the relations' scatter about the scale, as a ratio estimator's; 0 from fewer than
  /// two) and the relations it rests on. The relations are taken as independent: where they overlap in
  /// time (the benchmark's do) it is a lower bound.
  double along_track_scale_error = 0.0;
  int along_track_count = 0;
  /// Metres: well below most relations' motion, so that leaving out those the reference puts below it does
  /// not select the relations whose reference happens to move farther (at 0.5 m aces kept 18 of its 1178
  /// short relations, and the scale of both estimates read 0.92; from 0.1 m 1081 of them, 1.00).
  static constexpr double kScaleMinDistance = 0.1;
};

/// Index of the pose of `trajectory` (sorted by stamp) whose stamp is nearest to `stamp` if within
/// `tolerance` seconds, else -1.
long findStamp(const std::vector<StampedPose>& trajectory, double stamp, double tolerance);

/// Evaluates the relations whose span |t2 - t1| is at most `max_span` seconds (<= 0: all) against
/// `trajectory` (sorted by stamp). A relation's stamps must each match a trajectory stamp within
/// `stamp_tolerance` seconds, else it counts as missing.
RelationStats evaluateRelations(const std::vector<Relation>& relations,
                                const std::vector<StampedPose>& trajectory, double max_span,
                                double stamp_tolerance = 1e-3);

/// The same metric for relative motions estimated relation by relation: estimated[k] is the motion from
/// t1 to t2 of relations[k], used if valid[k] (else the relation counts as missing).
RelationStats evaluateRelativeMotions(const std::vector<Relation>& relations,
                                      const std::vector<Pose2D>& estimated, const std::vector<bool>& valid,
                                      double max_span);

/// The relative motions of `trajectory` between each relation's stamps (valid[k] false where a stamp is not
/// in it within `stamp_tolerance`).
void relativeMotions(const std::vector<Relation>& relations, const std::vector<StampedPose>& trajectory,
                     std::vector<Pose2D>* estimated, std::vector<bool>* valid, double stamp_tolerance = 1e-3);

/// Whether an estimate's clock and its turns agree with the reference's. An estimate whose pose at stamp t
/// is the robot's at t + offset has heading errors offset x (turn rate at t2 - turn rate at t1) over a
/// relation; one that counts every turn (1 + turn_scale) times has heading errors turn_scale x the
/// reference's turn (a laser whose bearings are spread wider than their stated angle increment, wheels
/// with a wrong wheel base). Both are fitted jointly by least squares over the relations spanning at most
/// `max_span` s (<= 0: all) — either alone would absorb part of the other, as relations that start or end
/// in a turn see both. Turn rates come from `turn_rates` (a trajectory, e.g. the wheels', differenced over
/// +-kTurnRateHalfWindow s). Relations whose heading error exceeds kMaxHeadingError are left out (a leap
/// is neither).
struct TimingFit {
  int count = 0;               ///< relations fitted
  double offset = 0.0;         ///< seconds; > 0: the estimate's pose at t is the reference's at a later time
  double offset_sd = 0.0;      ///< its standard error, seconds
  double turn_scale = 0.0;     ///< > 0: the estimate turns more than the reference, by this fraction
  double turn_scale_sd = 0.0;  ///< its standard error
  double rate_change = 0.0;    ///< rad/s: root mean square change of turn rate over the fitted relations
  static constexpr double kTurnRateHalfWindow = 0.3;  ///< seconds
  static constexpr double kMaxHeadingError = 0.05;    ///< radians (about 3 degrees)
};
TimingFit fitTimingOffset(const std::vector<Relation>& relations, const std::vector<Pose2D>& estimated,
                          const std::vector<bool>& valid, const std::vector<StampedPose>& turn_rates,
                          double max_span);

/// The relations (spanning at most `max_span` s; <= 0: all) that their own scans contradict: the scans
/// matched on their own from the reference's motion (`direct`) settle more than `min_disagreement` rad from
/// the reference's turn and within `max_agreement` rad of an independent witness's (`witness`, e.g. the
/// wheels'). A reference built by hand can be wrong; where the scans and the wheels agree against it, it
/// likely is.
std::vector<bool> contradictedRelations(const std::vector<Relation>& relations,
                                        const std::vector<Pose2D>& direct,
                                        const std::vector<bool>& direct_valid,
                                        const std::vector<Pose2D>& witness,
                                        const std::vector<bool>& witness_valid, double max_span,
                                        double min_disagreement, double max_agreement);

/// One relation's error (the residual estimated ⊖ reference).
struct RelationError {
  std::size_t index = 0;  ///< into the relations
  Pose2D residual;        ///< signed, in the frame of the reference's motion's end
  /// Metres.
  double trans() const { return residual.translationNorm(); }
  /// Absolute, degrees.
  double rotDeg() const { return std::abs(normalizeAngle(residual.theta)) * kRadToDeg; }
};

/// Per-relation errors of the relations spanning at most `max_span` s (<= 0: all) whose stamps are in
/// `trajectory`, in the order of `relations`.
std::vector<RelationError> relationErrors(const std::vector<Relation>& relations,
                                          const std::vector<StampedPose>& trajectory, double max_span,
                                          double stamp_tolerance = 1e-3);

/// How well a trajectory's stated uncertainty covers its errors: for each relation, the per-step increment
/// covariances from t1 to t2 composed (the covariance of the estimated relative motion) against the error
/// of that motion (coordinates in the t1 frame). With honest covariances the squared Mahalanobis distance
/// averages 3 (three degrees of freedom).
struct CalibrationStats {
  int count = 0;
  double mean_sq_mahalanobis = 0.0;
  double median_sq_mahalanobis = 0.0;
  double fraction_within_3dof_95 = 0.0;  ///< share of relations with squared distance <= 7.81
};

/// `increment_covariances[i]` is the covariance of the motion from trajectory[i-1] to trajectory[i] in
/// trajectory[i-1]'s frame (element 0 unused).
CalibrationStats evaluateCalibration(const std::vector<Relation>& relations,
                                     const std::vector<StampedPose>& trajectory,
                                     const std::vector<Eigen::Matrix3d>& increment_covariances,
                                     double max_span, double stamp_tolerance = 1e-3);

}  // namespace hglasm
