// What the matches teach about the sensors that predict the motion: the wheels' noise and the scan's
// (NoiseLearner), the wheels' systematic errors (WheelCalibration) and their time offset
// (TimeOffsetEstimator), and the IMU gyro's bias (GyroBiasEstimator). Two consecutive scans matched against
// the same map share most of their error, so the motion between where the scans alone put the base
// measures the step; against the wheels' and the IMU's it shows their errors.
#pragma once

#include <Eigen/Core>
#include <array>

#include "hglasm_odometry/core/gyro.h"
#include "hglasm_odometry/core/motion_model.h"
#include "hglasm_odometry/core/noise_learner.h"
#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/pose_extrapolator.h"
#include "hglasm_odometry/core/scan_information.h"
#include "hglasm_odometry/core/time_offset_estimator.h"
#include "hglasm_odometry/core/wheel_calibration.h"

namespace hglasm {

struct SensorLearningOptions {
  /// The wheels' noise and the scan's information are scaled by what the matches show.
  NoiseLearnerOptions noise;
  /// The wheels' systematic errors, learned from the matches and removed from their motion.
  WheelCalibrationOptions wheel_calibration;
  /// The wheels' stamps may run late against the scans': learned from the matches, or fixed.
  TimeOffsetOptions odometry_time_offset;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, SensorLearningOptions* options) {
  visitOptions(visitor, &options->odometry_time_offset);
  visitOptions(visitor, &options->noise);
  visitOptions(visitor, &options->wheel_calibration);
}

/// Where a matched scan alone put the base.
struct ScanOnlyPose {
  Pose2D pose;   ///< the base in the odometry frame
  Pose2D laser;  ///< the laser in the odometry frame (the same pose before any mount is applied)
  /// The covariance of `pose` that each eigen-direction of the scan's information contributes, weakest
  /// first (NoiseSample::scan_covariance).
  std::array<Eigen::Matrix3d, 3> covariance_parts;
  bool usable = false;  ///< finite, and the scan constrains every direction (not degenerate)
};

/// A snapshot of what is learned (for diagnostics).
struct LearnedModels {
  MotionNoiseScale wheel_noise;                        ///< the wheels' variance scales
  ScanNoiseScale scan_noise = ScanNoiseScale::Ones();  ///< the scan's, weakest direction first
  double wheel_turn_scale = 0.0;                       ///< the wheels' systematic errors (WheelCalibration)
  double wheel_heading_per_metre = 0.0;                ///< rad/m
  double wheel_distance_scale = 0.0;
  Eigen::Vector2d laser_offset = Eigen::Vector2d::Zero();  ///< m: the laser's learned place minus its mount's
  double imu_bias = 0.0;  ///< rad/s: the IMU gyro's bias, subtracted from its rotations
};

/// Not thread-safe per instance.
class SensorLearner {
 public:
  /// `wheel_noise`: the wheels' noise model whose scales are learned; `imu`: the IMU's, whose bias is.
  SensorLearner(const SensorLearningOptions& options, const MotionNoiseOptions& wheel_noise,
                const GyroOptions& imu);

  /// base -> laser as stated (tf): the laser's lever arm is learned against it.
  void setLaserMount(const Pose2D& base_to_laser) { stated_mount_ = base_to_laser; }

  /// A matched scan that ends the step `prediction` predicted, which started at `from` (seconds).
  /// `learn_wheels` false: the wheels were wrong beyond their noise (a leap), an outlier rather than noise;
  /// the IMU's bias is still learned (its filter clips what it cannot explain).
  void addMatchedScan(const MotionPrediction& prediction, double from, const ScanOnlyPose& scan,
                      bool learn_wheels);
  /// A scan without a match: the next matched scan has no step to compare.
  void addUnmatchedScan();
  /// The odometry restarts: the same, and the noise learner's chain of comparisons breaks (what is learned
  /// is kept).
  void restart();

  /// Learns the wheels' time offset from the last matched scan (stamped `stamp`, usable) against `wheels`.
  /// True when the offset in use changed: a large change forgets the wheels' learned noise and calibration
  /// (learned from predictions read at the wrong time, they were mostly the offset's).
  bool learnTimeOffset(double stamp, const OdometryBuffer& wheels);

  /// The last scan added was matched and usable (the time offset learns from it).
  bool lastScanUsable() const { return have_scan_rotation_; }

  const MotionNoiseModel& wheelNoise() const { return wheel_noise_; }
  ScanNoiseScale scanNoiseScale() const { return noise_learner_.scanScale(); }
  /// How many times the scan overstates its evidence overall (NoiseLearner::scanEvidenceScale).
  double scanEvidenceScale() const { return noise_learner_.scanEvidenceScale(); }
  const WheelCalibration& wheelCalibration() const { return calibration_; }
  const GyroBiasEstimator& imuBias() const { return imu_bias_; }
  const TimeOffsetEstimator& odometryTimeOffset() const { return time_offset_; }
  LearnedModels learned() const;

  /// Variance of the rotation between where two consecutive scans alone put the base (rad^2): two matches
  /// against the same map share most of their error; (2 mrad)^2 leaves room for a keyframe change between.
  static constexpr double kScanRotationVariance = 0.002 * 0.002;

 private:
  /// The learner's sample of a matched scan: where it alone put the base, the wheels' motion since the last.
  NoiseSample noiseSample(const MotionPrediction& prediction, const ScanOnlyPose& scan) const;
  /// The wheels' systematic errors from one step between two matched scans.
  void learnCalibration(const MotionPrediction& prediction, const ScanOnlyPose& scan,
                        const Eigen::Matrix3d& scan_covariance);
  void forgetWheelLearning();

  MotionNoiseModel wheel_noise_;
  NoiseLearner noise_learner_;
  WheelCalibration calibration_;
  GyroBiasEstimator imu_bias_;
  TimeOffsetEstimator time_offset_;

  Pose2D stated_mount_;
  Pose2D scan_pose_;   // where the last matched scan alone put the base (odometry frame)
  Pose2D scan_laser_;  // ... and the laser
  Eigen::Matrix3d scan_covariance_ = Eigen::Matrix3d::Zero();  // ... its covariance (wheel steps only)
  bool have_scan_rotation_ = false;  // scan_pose_ is usable (the IMU's bias learns from it)
  bool have_scan_pose_ = false;      // ... and the wheels predicted that scan (their noise learns from it)
};

}  // namespace hglasm
