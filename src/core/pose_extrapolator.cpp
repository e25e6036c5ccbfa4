#include "hglasm_odometry/core/pose_extrapolator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace hglasm {

const char* toString(PredictionSource source) {
  switch (source) {
    case PredictionSource::kOdometry:
      return "odometry";
    case PredictionSource::kConstantVelocity:
      return "constant_velocity";
    case PredictionSource::kNone:
      return "none";
  }
  return "unknown";
}

PoseExtrapolator::PoseExtrapolator(bool use_odometry, double max_odometry_age, double max_speed,
                                   double max_turn_rate, bool use_gyro, const GyroOptions& gyro)
    : use_odometry_(use_odometry),
      max_odometry_age_(max_odometry_age),
      max_speed_(max_speed),
      max_turn_rate_(max_turn_rate),
      use_gyro_(use_gyro),
      gyro_(gyro),
      gyro_bias_variance_(gyro.bias * gyro.bias) {}

MotionPrediction PoseExtrapolator::predict(double from, double to, const MotionNoiseModel& noise,
                                           std::string* warning) const {
  MotionPrediction prediction = predictTranslation(from, to, noise, warning);
  prediction.dt = to - from;
  if (use_gyro_) applyGyro(from, to, &prediction);
  return prediction;
}

void PoseExtrapolator::applyGyro(double from, double to, MotionPrediction* prediction) const {
  double raw_angle = 0.0;
  if (!gyro_.rotation(from, to, &raw_angle)) return;
  const double angle = raw_angle - gyro_bias_ * (to - from);
  // Along an arc the chord turns by half the rotation: with the rotation corrected, so is the chord.
  const double correction = 0.5 * (angle - prediction->motion.theta);
  const double c = std::cos(correction), s = std::sin(correction);
  const Pose2D& motion = prediction->motion;
  prediction->motion = Pose2D(c * motion.x - s * motion.y, s * motion.x + c * motion.y, angle);
  // The heading's noise is the IMU's alone, independent of the translation's.
  for (Eigen::Matrix3d* covariance : {&prediction->covariance, &prediction->nominal_covariance}) {
    covariance->row(2).setZero();
    covariance->col(2).setZero();
  }
  prediction->covariance(2, 2) = gyroRotationVariance(gyro_.options(), angle, to - from, gyro_bias_variance_);
  prediction->gyro = true;
}

MotionPrediction PoseExtrapolator::predictTranslation(double from, double to, const MotionNoiseModel& noise,
                                                      std::string* warning) const {
  MotionPrediction prediction;
  const double dt = to - from;
  Pose2D odom_from, odom_to;
  if (use_odometry_ && odometry_.poseAt(from, max_odometry_age_, &odom_from) &&
      odometry_.poseAt(to, max_odometry_age_, &odom_to)) {
    const Pose2D motion = relativePose(odom_from, odom_to);
    const bool plausible = motion.translationNorm() <= max_speed_ * dt + 0.2 &&
                           std::abs(motion.theta) <= max_turn_rate_ * dt + 0.2;
    if (plausible) {
      prediction.source = PredictionSource::kOdometry;
      prediction.motion = motion;
      prediction.covariance = noise.odometryCovariance(motion, dt);
      prediction.nominal_covariance = noise.nominalOdometryCovariance(motion, dt);
      return prediction;
    }
    std::ostringstream text;
    text << "wheel odometry jumped " << motion.translationNorm() << " m / " << motion.theta << " rad in "
         << dt << " s; using the constant-velocity prediction";
    *warning = text.str();
  }
  prediction.covariance = noise.constantVelocityCovariance(dt);
  if (velocity_known_) {
    prediction.source = PredictionSource::kConstantVelocity;
    prediction.motion = Pose2D(velocity_.x() * dt, velocity_.y() * dt, velocity_.z() * dt);
  }
  return prediction;
}

double PoseExtrapolator::addPose(double stamp, const Pose2D& pose) {
  poses_.push_back(StampedPose{stamp, pose});
  while (poses_.size() > 2 && stamp - poses_[1].stamp >= kVelocityBaseline) poses_.pop_front();
  const double baseline = stamp - poses_.front().stamp;
  if (!(baseline >= kVelocityBaseline && baseline <= kMaxVelocityAge)) {
    if (baseline > kMaxVelocityAge) velocity_known_ = false;
    return 0.0;
  }
  const Pose2D motion = relativePose(poses_.front().pose, pose);
  Eigen::Vector3d velocity(motion.x / baseline, motion.y / baseline, motion.theta / baseline);
  const double speed = velocity.head<2>().norm();
  if (speed > max_speed_) velocity.head<2>() *= max_speed_ / speed;
  velocity.z() = std::clamp(velocity.z(), -max_turn_rate_, max_turn_rate_);
  velocity_ = velocity;
  velocity_known_ = true;
  return baseline;
}

void PoseExtrapolator::reset() {
  poses_.clear();
  velocity_.setZero();
  velocity_known_ = false;
}

}  // namespace hglasm
