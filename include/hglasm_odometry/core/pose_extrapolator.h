// The motion of the base between two scans, predicted before the scan is matched (as Cartographer's
// PoseExtrapolator): by wheel odometry when it covers both stamps and moves plausibly, else at the
// velocity of the recent estimates, its rotation from an IMU when one covers both stamps; and that
// velocity, which also de-skews the scans.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <deque>
#include <string>

#include "hglasm_odometry/core/gyro.h"
#include "hglasm_odometry/core/motion_model.h"
#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/wheel_calibration.h"

namespace hglasm {

enum class PredictionSource { kOdometry, kConstantVelocity, kNone };
const char* toString(PredictionSource source);

/// The predicted motion of the base between two stamps, in its frame at the first, and its noise.
struct MotionPrediction {
  PredictionSource source = PredictionSource::kNone;
  double dt = 0.0;  ///< seconds the motion spans
  Pose2D motion;
  /// The wheels' own motion, before their learned systematic errors were removed (identity without them).
  Pose2D wheel_motion;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  /// The wheels' part at unit noise scale (for learning their noise): zero where they predicted nothing.
  Eigen::Matrix3d nominal_covariance = Eigen::Matrix3d::Zero();
  /// The rotation (and its variance) came from the IMU; the translation is the wheels' (or the velocity's)
  /// turned by half the difference of the two rotations, as the chord of an arc turns with it.
  bool rotation_from_imu = false;
};

struct PoseExtrapolatorOptions {
  bool use_odometry = true;                  ///< predict from wheel odometry at all
  double max_odometry_extrapolation = 0.25;  ///< seconds past the newest wheel sample; beyond, it is stale
  /// Wheel motion faster than this between two scans, plus a margin of 0.2 m / 0.2 rad for jitter, is
  /// implausible (a jump): the velocity predicts instead. The velocity is capped at both too.
  double max_speed = 5.0;      ///< m/s
  double max_turn_rate = 6.0;  ///< rad/s
  /// Take the rotation from the IMU (addImu) whenever its samples cover the interval, with `imu`'s noise
  /// model; the wheels (or the velocity) predict the translation, and the rotation while the IMU is stale.
  bool use_imu = false;
  GyroOptions imu;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, PoseExtrapolatorOptions* options) {
  visitor.boolean("use_odom", &options->use_odometry);
  visitor.boolean("use_imu", &options->use_imu);
  visitor.nonNegativeNumber("odometry/max_extrapolation", &options->max_odometry_extrapolation);
  visitor.positiveNumber("odometry/max_speed", &options->max_speed);
  visitor.positiveNumber("odometry/max_turn_rate", &options->max_turn_rate);
  visitOptions(visitor, &options->imu);
}

/// Not thread-safe per instance.
class PoseExtrapolator {
 public:
  explicit PoseExtrapolator(const PoseExtrapolatorOptions& options = {});
  const PoseExtrapolatorOptions& options() const { return options_; }

  /// Wheel odometry: pose of the base in the wheel-odometry frame at `stamp`.
  void addOdometry(double stamp, const Pose2D& pose) { odometry_.add(stamp, pose); }
  /// IMU: the base's yaw rate (rad/s), or its yaw (rad) with GyroOptions::use_orientation, at `stamp`.
  /// Ignored (false) without use_imu or for non-finite values.
  bool addImu(double stamp, double value) { return options_.use_imu && imu_.add(stamp, value); }
  /// The IMU gyro's bias (rad/s) and its variance, subtracted from the IMU's rotations from now on.
  void setImuBias(double bias, double variance) {
    imu_bias_ = bias;
    imu_bias_variance_ = variance;
  }
  /// The IMU's rotation of the base from `from` to `to` (bias removed); false without use_imu or when the
  /// samples do not cover the interval.
  bool imuRotation(double from, double to, double* angle) const;
  /// Forgets the wheel odometry (its samples belong to another timeline: its clock went back).
  void clearOdometry() { odometry_.clear(); }
  /// The next prediction starts at the scan stamped `stamp`: the wheels' pose then (at `stamp` plus their
  /// time offset, whatever offset up to `max_offset` is learned meanwhile) stays available.
  void startNextPredictionAt(double stamp, double max_offset) {
    odometry_.keepAround(stamp + odometry_time_offset_, std::abs(max_offset) + 0.5);
    imu_.forgetBefore(stamp);
  }
  /// Forgets the IMU samples (another timeline).
  void clearImu() { imu_.clear(); }
  const OdometryBuffer& odometry() const { return odometry_; }

  /// The wheels' systematic errors, removed from their motion before it predicts (learned by the caller).
  void setWheelCalibration(const WheelCalibration& calibration) { calibration_ = calibration; }

  /// Seconds the wheels' stamps run late: their pose of a scan's instant t is read at t + offset.
  void setOdometryTimeOffset(double offset) { odometry_time_offset_ = offset; }
  double odometryTimeOffset() const { return odometry_time_offset_; }

  /// The motion of the base from `from` to `to`, with `noise`'s covariance. Sets *warning when the wheels
  /// jumped (the velocity predicts instead) or the IMU turned implausibly fast (it is not used). Without
  /// wheels over a step longer than kMaxVelocityAge the recent velocity says nothing: no motion is
  /// predicted (source kNone), with the constant-velocity noise of kMaxVelocityAge.
  MotionPrediction predict(double from, double to, const MotionNoiseModel& noise, std::string* warning) const;

  /// A new estimate of the base pose. The velocity becomes the motion over the last kVelocityBaseline
  /// seconds or more; returns that baseline, or 0 if there is none yet (then the velocity is kept, and
  /// forgotten once the newest older pose is kMaxVelocityAge old).
  double addPose(double stamp, const Pose2D& pose);

  bool velocityKnown() const { return velocity_known_; }
  /// vx, vy, wz of the base in its own frame.
  const Eigen::Vector3d& velocity() const { return velocity_; }

  /// Forgets the poses and the velocity; the wheel odometry is kept.
  void reset();

  /// Some logs hold bursts of scans ~1 ms apart whose stamps do not match their motion: a velocity over a
  /// shorter baseline would explode.
  static constexpr double kVelocityBaseline = 0.1;  // seconds
  static constexpr double kMaxVelocityAge = 2.0;    // seconds: older motion says nothing about the speed now

 private:
  /// A turn of `angle` in `dt` seconds within max_turn_rate (plus kJitterMargin), whoever measured it.
  bool plausibleTurn(double angle, double dt) const {
    return std::abs(angle) <= options_.max_turn_rate * dt + kJitterMargin;
  }
  static constexpr double kJitterMargin = 0.2;  // m or rad a plausible motion may exceed its rate bound by
  /// The wheels' or the velocity's prediction.
  MotionPrediction predictTranslation(double from, double to, const MotionNoiseModel& noise,
                                      std::string* warning) const;
  /// Replaces the prediction's rotation by the IMU's, if it covers [from, to] and turns plausibly (else
  /// sets *warning).
  void applyImu(double from, double to, MotionPrediction* prediction, std::string* warning) const;

  PoseExtrapolatorOptions options_;
  OdometryBuffer odometry_;
  GyroBuffer imu_;
  double odometry_time_offset_ = 0.0;
  WheelCalibration calibration_;
  double imu_bias_ = 0.0;
  double imu_bias_variance_;
  std::deque<StampedPose> poses_;  // recent estimates, for the velocity
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();
  bool velocity_known_ = false;
};

}  // namespace hglasm
