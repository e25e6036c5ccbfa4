// The wheels' systematic errors, learned from the scans: a turn-rate scale (a wrong wheel base), a heading
// drift per metre travelled (wheels of slightly different size) and a distance scale (a wrong wheel
// radius). Noise averages out over a log; these add up, and are what makes even good-looking wheels drift.
// By default only the turn scale is learned: the scans see rotation well in every turn, while a drift per
// metre is confounded with their own slow heading error and a distance scale with their bias along
// corridors (doc/accuracy.md, "Ablation").
#pragma once

#include <Eigen/Core>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

struct WheelCalibrationOptions {
  bool learn = true;
  double half_life = 2000.0;  ///< matched scans after which an old step counts half (temperature, load)
  /// Standard deviations of the errors before anything is learned (how miscalibrated wheels may be); 0: that
  /// error is taken as none and not learned.
  double turn_scale = 0.1;         ///< fraction of the turn
  double heading_per_metre = 0.0;  ///< rad/m
  double distance_scale = 0.0;     ///< fraction of the distance
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, WheelCalibrationOptions* options) {
  visitor.boolean("odometry/calibration/learn", &options->learn);
  visitor.positiveNumber("odometry/calibration/half_life", &options->half_life);
  visitor.nonNegativeNumber("odometry/calibration/turn_scale", &options->turn_scale);
  visitor.nonNegativeNumber("odometry/calibration/heading_per_metre", &options->heading_per_metre);
  visitor.nonNegativeNumber("odometry/calibration/distance_scale", &options->distance_scale);
}

/// Recursive least squares on the steps between consecutive matched scans: the heading the scans saw turned
/// against the wheels' (turn_scale * turn + heading_per_metre * distance), and the distance along the
/// wheels' direction against theirs (distance_scale * distance). Not thread-safe per instance.
class WheelCalibration {
 public:
  explicit WheelCalibration(const WheelCalibrationOptions& options = {});

  /// The wheels' motion over a step with their learned systematic errors removed: the turn scaled and the
  /// drift added, the translation scaled and turned as the chord of the corrected arc.
  Pose2D correct(const Pose2D& wheel_motion) const;

  /// One step: the wheels' raw motion, the motion between where the two scans alone put the base, and the
  /// variance of their difference in heading and along the track (both noises; <= 0: that part says
  /// nothing, e.g. the heading when an IMU gave it). Steps the model cannot explain (beyond 4 sigma: a
  /// slip, a bad match) are left out.
  void learn(const Pose2D& wheel_motion, const Pose2D& scan_motion, double heading_variance,
             double distance_variance);

  /// Forgets what was learned.
  void reset();

  double headingPerMetre() const { return heading_[1]; }
  double turnScale() const { return heading_[0]; }
  double distanceScale() const { return distance_; }
  const WheelCalibrationOptions& options() const { return options_; }

 private:
  WheelCalibrationOptions options_;
  // Information form of the estimates, forgotten towards the prior.
  Eigen::Vector2d heading_ = Eigen::Vector2d::Zero();  // turn scale, heading per metre
  Eigen::Matrix2d heading_information_;
  Eigen::Vector2d heading_vector_ = Eigen::Vector2d::Zero();
  double distance_ = 0.0;
  double distance_information_ = 0.0;
  double distance_vector_ = 0.0;
};

}  // namespace hglasm
