#include "hglasm_odometry/core/sensor_learner.h"

#include <cmath>

namespace hglasm {

SensorLearner::SensorLearner(const SensorLearningOptions& options, const MotionNoiseOptions& wheel_noise,
                             const GyroOptions& imu)
    : wheel_noise_(wheel_noise),
      noise_learner_(options.noise),
      calibration_(options.wheel_calibration),
      imu_bias_(imu),
      time_offset_(options.odometry_time_offset) {}

NoiseSample SensorLearner::noiseSample(const MotionPrediction& prediction, const ScanOnlyPose& scan) const {
  NoiseSample sample;
  sample.scan_pose = scan.pose;
  sample.scan_covariance = scan.covariance_parts;
  sample.wheel_motion = prediction.motion;
  // The nominal covariance's translation block scales with the wheels' translation noise, its heading
  // with their heading noise (zero where an IMU gave the rotation); the rest (the IMU's) is known.
  sample.wheel_xy = prediction.nominal_covariance;
  sample.wheel_xy.row(2).setZero();
  sample.wheel_xy.col(2).setZero();
  sample.wheel_theta(2, 2) = prediction.nominal_covariance(2, 2);
  sample.wheel_known = prediction.covariance - wheel_noise_.scale().xy * sample.wheel_xy -
                       wheel_noise_.scale().theta * sample.wheel_theta;
  return sample;
}

void SensorLearner::learnCalibration(const MotionPrediction& prediction, const ScanOnlyPose& scan,
                                     const Eigen::Matrix3d& scan_covariance) {
  // The step's innovation variance: the wheels' noise and both scans' (heading; along the track, the
  // larger translation variance of each: the direction of travel is unknown here).
  const Eigen::Matrix3d scans = scan_covariance + scan_covariance_;
  const double heading_variance = prediction.covariance(2, 2) + scans(2, 2);
  // The translation block in the base frame where the step starts (the scans' covariances are of the
  // odometry frame, the prediction's of that base frame), and its larger eigenvalue in closed form.
  const double c = std::cos(scan_pose_.theta), s = std::sin(scan_pose_.theta);
  Eigen::Matrix2d to_base;
  to_base << c, s, -s, c;
  const Eigen::Matrix2d translation = prediction.covariance.topLeftCorner<2, 2>() +
                                      to_base * scans.topLeftCorner<2, 2>() * to_base.transpose();
  const double half_trace = 0.5 * (translation(0, 0) + translation(1, 1));
  const double larger =
      half_trace + std::hypot(0.5 * (translation(0, 0) - translation(1, 1)), translation(0, 1));
  // An IMU gave the rotation: the wheels' turn says nothing about their heading errors.
  calibration_.learn(prediction.wheel_motion, relativePose(scan_pose_, scan.pose),
                     prediction.rotation_from_imu ? -1.0 : heading_variance, larger);
  calibration_.learnLaserOffset(prediction.wheel_motion, relativePose(scan_laser_, scan.laser), stated_mount_,
                                translation);
}

void SensorLearner::addMatchedScan(const MotionPrediction& prediction, double from, const ScanOnlyPose& scan,
                                   bool learn_wheels) {
  const bool usable = learn_wheels && prediction.source == PredictionSource::kOdometry && scan.usable;
  Eigen::Matrix3d scan_covariance = Eigen::Matrix3d::Zero();
  if (usable) {
    if (!have_scan_pose_) noise_learner_.breakChain();
    const NoiseSample sample = noiseSample(prediction, scan);
    noise_learner_.add(sample);
    wheel_noise_.setScale(noise_learner_.wheelScale());
    for (const Eigen::Matrix3d& part : sample.scan_covariance) scan_covariance += part;
    if (have_scan_pose_) learnCalibration(prediction, scan, scan_covariance);
  } else {
    noise_learner_.breakChain();
  }
  scan_covariance_ = scan_covariance;
  if (scan.usable && have_scan_rotation_ && prediction.rotation_from_imu) {
    const Pose2D scan_motion = relativePose(scan_pose_, scan.pose);
    imu_bias_.update(prediction.motion.theta, scan_motion.theta, kScanRotationVariance, prediction.dt,
                     from + prediction.dt);
  }
  have_scan_pose_ = usable;
  have_scan_rotation_ = scan.usable;
  scan_pose_ = scan.pose;
  scan_laser_ = scan.laser;
}

void SensorLearner::addUnmatchedScan() { have_scan_pose_ = have_scan_rotation_ = false; }

void SensorLearner::restart() {
  addUnmatchedScan();
  noise_learner_.breakChain();
}

bool SensorLearner::learnTimeOffset(double stamp, const OdometryBuffer& wheels) {
  time_offset_.addScanPose(stamp, scan_pose_);
  const double before = time_offset_.offset();
  if (!time_offset_.update(wheels)) return false;
  if (std::abs(time_offset_.offset() - before) >= TimeOffsetEstimator::kMinOffset) forgetWheelLearning();
  return true;
}

void SensorLearner::forgetWheelLearning() {
  noise_learner_.reset();
  calibration_.reset();
  wheel_noise_.setScale(noise_learner_.wheelScale());
}

LearnedModels SensorLearner::learned() const {
  LearnedModels learned;
  learned.wheel_noise = wheel_noise_.scale();
  learned.scan_noise = noise_learner_.scanScale();
  learned.wheel_turn_scale = calibration_.turnScale();
  learned.wheel_heading_per_metre = calibration_.headingPerMetre();
  learned.wheel_distance_scale = calibration_.distanceScale();
  learned.laser_offset = calibration_.laserOffset();
  learned.imu_bias = imu_bias_.bias();
  return learned;
}

}  // namespace hglasm
