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

PoseExtrapolator::PoseExtrapolator(const PoseExtrapolatorOptions& options)
    : options_(options),
      imu_(options.imu),
      imu_bias_variance_(options.imu.bias_sigma * options.imu.bias_sigma) {}

MotionPrediction PoseExtrapolator::predict(double from, double to, const MotionNoiseModel& noise,
                                           std::string* warning) const {
  MotionPrediction prediction = predictTranslation(from, to, noise, warning);
  prediction.dt = to - from;
  if (options_.use_imu) applyImu(from, to, &prediction, warning);
  return prediction;
}

bool PoseExtrapolator::imuRotation(double from, double to, double* angle) const {
  double raw_angle = 0.0;
  if (!options_.use_imu || !imu_.rotation(from, to, &raw_angle)) return false;
  *angle = raw_angle - imu_bias_ * (to - from);
  return true;
}

void PoseExtrapolator::applyImu(double from, double to, MotionPrediction* prediction,
                                std::string* warning) const {
  double angle = 0.0;
  if (!imuRotation(from, to, &angle)) return;
  const double dt = to - from;
  if (!plausibleTurn(angle, dt)) {
    std::ostringstream text;
    text << "IMU rotation of " << angle << " rad in " << dt << " s is faster than odometry/max_turn_rate; "
         << "the rotation is predicted without it";
    if (warning->empty()) *warning = text.str();
    return;
  }
  // Along an arc the chord turns by half the rotation: with the rotation corrected, so is the chord.
  const double correction = 0.5 * normalizeAngle(angle - prediction->motion.theta);
  const double c = std::cos(correction), s = std::sin(correction);
  const Eigen::Vector2d chord(c * prediction->motion.x - s * prediction->motion.y,
                              s * prediction->motion.x + c * prediction->motion.y);
  prediction->motion = Pose2D(chord.x(), chord.y(), angle);
  // First order: the chord turned by the correction, and moved by half of any error of the rotation.
  Eigen::Matrix3d turn = Eigen::Matrix3d::Zero();
  turn.topLeftCorner<2, 2>() << c, -s, s, c;
  const Eigen::Vector3d chord_per_radian(-0.5 * chord.y(), 0.5 * chord.x(), 1.0);
  const double angle_variance = gyroRotationVariance(imu_.options(), angle, dt, imu_bias_variance_);
  for (Eigen::Matrix3d* covariance : {&prediction->covariance, &prediction->nominal_covariance}) {
    const Eigen::Matrix2d translation = covariance->topLeftCorner<2, 2>();
    covariance->setZero();
    covariance->topLeftCorner<2, 2>() =
        turn.topLeftCorner<2, 2>() * translation * turn.topLeftCorner<2, 2>().transpose();
  }
  // The heading's noise is the IMU's alone (the wheels' heading noise is not learned from this step).
  prediction->covariance += angle_variance * chord_per_radian * chord_per_radian.transpose();
  prediction->rotation_from_imu = true;
}

MotionPrediction PoseExtrapolator::predictTranslation(double from, double to, const MotionNoiseModel& noise,
                                                      std::string* warning) const {
  MotionPrediction prediction;
  const double dt = to - from;
  Pose2D odom_from, odom_to;
  const double shift = odometry_time_offset_;
  double outside_from = 0.0, outside_to = 0.0;
  const double max_age = options_.max_odometry_extrapolation;
  if (options_.use_odometry && odometry_.poseAt(from + shift, max_age, &odom_from, &outside_from) &&
      odometry_.poseAt(to + shift, max_age, &odom_to, &outside_to)) {
    const Pose2D motion = relativePose(odom_from, odom_to);
    const bool plausible = motion.translationNorm() <= options_.max_speed * dt + kJitterMargin &&
                           plausibleTurn(motion.theta, dt);
    if (plausible) {
      prediction.source = PredictionSource::kOdometry;
      prediction.wheel_motion = motion;
      prediction.motion = calibration_.correct(motion);
      prediction.covariance = noise.odometryCovariance(prediction.motion, dt);
      prediction.nominal_covariance = noise.nominalOdometryCovariance(prediction.motion, dt);
      // Where the samples do not reach (held before the first, extrapolated after the last) the wheels'
      // motion is a guess at constant velocity, as uncertain as one.
      if (outside_from + outside_to > 0.0) {
        prediction.covariance += noise.constantVelocityCovariance(outside_from + outside_to);
      }
      return prediction;
    }
    std::ostringstream text;
    text << "wheel odometry jumped " << motion.translationNorm() << " m / " << motion.theta << " rad in "
         << dt << " s; using the constant-velocity prediction";
    *warning = text.str();
  }
  // After a pause longer than the velocity's memory the robot may have stopped or turned: the pose is
  // kept, as uncertain as the velocity's memory allows (the search is the preset's box).
  prediction.covariance = noise.constantVelocityCovariance(std::min(dt, kMaxVelocityAge));
  if (velocity_known_ && dt <= kMaxVelocityAge) {
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
  if (speed > options_.max_speed) velocity.head<2>() *= options_.max_speed / speed;
  velocity.z() = std::clamp(velocity.z(), -options_.max_turn_rate, options_.max_turn_rate);
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
