// The wheels' systematic errors, learned from the scans: a turn-rate scale (a wrong wheel base), a heading
// drift per metre travelled (wheels of slightly different size), a distance scale (a wrong wheel radius)
// and where the laser really sits on the base the wheels turn (a mount off by a lever arm). Noise averages
// out over a log; these add up, and are what makes even good-looking wheels drift.
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
  /// m: how far the laser may sit from where the mount (tf) puts it, in x and y of the base; 0: the mount
  /// is exact. In every turn the laser's own translation says where it sits relative to the point the
  /// wheels turn about (a 2-D hand-eye calibration); the tracker then matches with the learned place. A
  /// wrong lever arm makes scans and wheels disagree sideways in turns, which the fusion turns into a
  /// heading error; learned only while it is used, since the fusion otherwise hides part of it in the
  /// heading (doc/accuracy.md, "The laser's lever arm").
  double laser_offset = 0.0;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, WheelCalibrationOptions* options) {
  visitor.boolean("odometry/calibration/learn", &options->learn);
  visitor.positiveNumber("odometry/calibration/half_life", &options->half_life);
  visitor.nonNegativeNumber("odometry/calibration/turn_scale", &options->turn_scale);
  visitor.nonNegativeNumber("odometry/calibration/heading_per_metre", &options->heading_per_metre);
  visitor.nonNegativeNumber("odometry/calibration/distance_scale", &options->distance_scale);
  visitor.nonNegativeNumber("odometry/calibration/laser_offset", &options->laser_offset);
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

  /// One step seen by the laser: the wheels' raw motion, the laser's own motion, the mount the laser is
  /// stated at (base -> laser) and the 2 x 2 covariance of the translations' difference in the base frame
  /// (both noises). Learns where the laser sits: with the stated mount the scans' base motion differs from
  /// the wheels' by (R(turn) - I) times the mount's error. Steps the model cannot explain are left out.
  void learnLaserOffset(const Pose2D& wheel_motion, const Pose2D& laser_motion, const Pose2D& stated_mount,
                        const Eigen::Matrix2d& covariance);

  /// Forgets what was learned.
  void reset();

  double headingPerMetre() const { return heading_[1]; }
  double turnScale() const { return heading_[0]; }
  double distanceScale() const { return distance_; }
  /// m, in the base frame: where the laser sits minus where the stated mount puts it.
  const Eigen::Vector2d& laserOffset() const { return offset_; }
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
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();
  Eigen::Matrix2d offset_information_;
  Eigen::Vector2d offset_vector_ = Eigen::Vector2d::Zero();
};

}  // namespace hglasm
