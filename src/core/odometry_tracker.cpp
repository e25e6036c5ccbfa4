#include "hglasm_odometry/core/odometry_tracker.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace hglasm {
namespace {

constexpr double kMaxVariance = 1e4;
// The velocity is the motion over the last kVelocityBaseline seconds or more: some logs hold bursts of
// scans ~1 ms apart whose stamps do not match their motion, and a per-step velocity would explode.
constexpr double kVelocityBaseline = 0.1;  // seconds
constexpr double kMaxVelocityAge = 2.0;    // seconds: older motion says nothing about the current speed

/// Covariance of a ⊕ b from the covariances of a (parent frame) and b (a's frame), first order.
Eigen::Matrix3d composeCovariance(const Pose2D& a, const Eigen::Matrix3d& cov_a, const Pose2D& b,
                                  const Eigen::Matrix3d& cov_b) {
  const Pose2D ab = a * b;
  Eigen::Matrix3d j_a = Eigen::Matrix3d::Identity();
  j_a(0, 2) = -(ab.y - a.y);
  j_a(1, 2) = ab.x - a.x;
  Eigen::Matrix3d j_b = Eigen::Matrix3d::Identity();
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  j_b.topLeftCorner<2, 2>() << c, -s, s, c;
  Eigen::Matrix3d cov = j_a * cov_a * j_a.transpose() + j_b * cov_b * j_b.transpose();
  cov = 0.5 * (cov + cov.transpose());
  return cov.cwiseMin(kMaxVariance).cwiseMax(-kMaxVariance);
}

/// Covariance of a laser motion L re-expressed for the base motion B = M ⊕ L ⊕ M^-1 (first order):
/// dB_t/dL_t = R_M, dB_t/dL_theta = -S R_L t_M (S = 90-degree rotation), dB_theta/dL_theta = 1.
Eigen::Matrix3d laserToBaseCovariance(const Pose2D& mount, const Pose2D& laser_motion, const Eigen::Matrix3d& cov) {
  const double cm = std::cos(mount.theta), sm = std::sin(mount.theta);
  const double cl = std::cos(laser_motion.theta), sl = std::sin(laser_motion.theta);
  const Eigen::Vector2d rotated_lever(cl * mount.x - sl * mount.y, sl * mount.x + cl * mount.y);
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Identity();
  jacobian.topLeftCorner<2, 2>() << cm, -sm, sm, cm;
  jacobian(0, 2) = rotated_lever.y();
  jacobian(1, 2) = -rotated_lever.x();
  return jacobian * cov * jacobian.transpose();
}

Eigen::Matrix3d odometryNoise(const TrackerOptions& options, const Pose2D& motion) {
  const double sigma_xy = options.odometry_noise_xy * motion.translationNorm() + 0.01;
  const double sigma_theta = options.odometry_noise_theta * std::abs(motion.theta) + 0.005;
  return Eigen::Vector3d(sigma_xy * sigma_xy, sigma_xy * sigma_xy, sigma_theta * sigma_theta).asDiagonal();
}

/// The laser's velocity (vx, vy, omega in the laser frame) from the base's (base frame): the lever arm
/// of the mount adds omega x t to the translation.
Eigen::Vector3d laserVelocity(const Pose2D& mount, const Eigen::Vector3d& base_velocity) {
  const double omega = base_velocity.z();
  const Eigen::Vector2d at_laser(base_velocity.x() - omega * mount.y, base_velocity.y() + omega * mount.x);
  const double c = std::cos(mount.theta), s = std::sin(mount.theta);
  return Eigen::Vector3d(c * at_laser.x() + s * at_laser.y(), -s * at_laser.x() + c * at_laser.y(), omega);
}

/// Information-weighted mean of a degenerate match and the prediction (both base motions since the
/// keyframe, first order in the keyframe frame): the match decides the directions it constrains, the
/// prediction the one it does not (along a featureless corridor). Covariances must be positive definite.
Pose2D fuseWithPrediction(const Pose2D& match, const Eigen::Matrix3d& match_cov, const Pose2D& prediction,
                          const Eigen::Matrix3d& prediction_cov, Eigen::Matrix3d* fused_cov) {
  const Eigen::Matrix3d match_info = match_cov.inverse();
  const Eigen::Matrix3d fused = (match_info + prediction_cov.inverse()).inverse();
  const Eigen::Vector3d innovation(match.x - prediction.x, match.y - prediction.y,
                                   normalizeAngle(match.theta - prediction.theta));
  const Eigen::Vector3d correction = fused * match_info * innovation;
  *fused_cov = 0.5 * (fused + fused.transpose());
  return Pose2D(prediction.x + correction.x(), prediction.y + correction.y(), prediction.theta + correction.z());
}

}  // namespace

const char* toString(PredictionSource source) {
  switch (source) {
    case PredictionSource::kOdometry: return "odometry";
    case PredictionSource::kConstantVelocity: return "constant_velocity";
    case PredictionSource::kNone: return "none";
  }
  return "unknown";
}

OdometryTracker::OdometryTracker(const TrackerOptions& options) : options_(options), matcher_(options.matcher) {}

void OdometryTracker::setLaserMount(const Pose2D& base_to_laser) {
  if (base_to_laser.isFinite()) laser_mount_ = base_to_laser;
}

void OdometryTracker::addOdometry(double stamp, const Pose2D& odom_pose) { odometry_.add(stamp, odom_pose); }

void OdometryTracker::reset() {
  initialised_ = false;
  has_keyframe_ = false;
  pose_ = Pose2D();
  pose_covariance_.setZero();
  velocity_.setZero();
  velocity_valid_ = false;
  recent_fitness_ = 0.0;
  history_.clear();
}

void OdometryTracker::guardAgainstJump(const Scan& scan, const Pose2D& laser_guess, PredictionSource prediction,
                                       TrackerUpdate* update) {
  if (prediction == PredictionSource::kNone || !usesGeneticStage(options_.matcher.algorithm)) return;
  // The guess relative to the keyframe is the predicted motion since the keyframe.
  const auto far_from_guess = [&](const Pose2D& pose) {
    const Pose2D deviation = relativePose(laser_guess, pose);
    return deviation.translationNorm() > options_.jump_distance + options_.jump_fraction * laser_guess.translationNorm() ||
           std::abs(deviation.theta) > options_.jump_angle + options_.jump_fraction * std::abs(laser_guess.theta);
  };
  if (!far_from_guess(update->match.pose)) return;
  const double jump_fitness = matcher_.fitnessRatioAt(scan, update->match.pose);
  const MatchResult from_guess = matcher_.refine(scan, laser_guess);
  const bool guess_refined = (from_guess.status == MatchStatus::kOk ||
                              from_guess.status == MatchStatus::kMbicpNotConverged) &&
                             !far_from_guess(from_guess.pose);
  if (jump_fitness >= options_.jump_min_relative_fitness * recent_fitness_ &&
      (!guess_refined || jump_fitness > from_guess.fitness_ratio + options_.jump_margin)) {
    return;  // a convincing leap: the prediction was wrong (wheel slip, a kidnapped robot)
  }
  update->jump_rejected = true;
  if (!guess_refined) {
    update->match.status = MatchStatus::kLowFitness;  // neither is convincing: fall back to the prediction
    return;
  }
  MatchResult kept = from_guess;
  kept.prealign_ms = update->match.prealign_ms;
  kept.refine_ms += update->match.refine_ms;
  kept.evaluations = update->match.evaluations;
  kept.prealigned_pose = update->match.prealigned_pose;
  update->match = kept;
}

PredictionSource OdometryTracker::predict(double stamp, Pose2D* predicted, std::string* warning) const {
  const double dt = stamp - last_stamp_;
  if (options_.use_odometry) {
    Pose2D odom_last, odom_now;
    const double reach = options_.odometry_max_extrapolation;
    if (odometry_.poseAt(last_stamp_, reach, &odom_last) && odometry_.poseAt(stamp, reach, &odom_now)) {
      const Pose2D motion = relativePose(odom_last, odom_now);
      const bool plausible = motion.translationNorm() <= options_.max_odometry_speed * dt + 0.2 &&
                             std::abs(motion.theta) <= options_.max_odometry_turn_rate * dt + 0.2;
      if (plausible) {
        *predicted = pose_ * motion;
        return PredictionSource::kOdometry;
      }
      std::ostringstream text;
      text << "wheel odometry jumped " << motion.translationNorm() << " m / " << motion.theta << " rad in " << dt
           << " s; using the constant-velocity prediction";
      *warning = text.str();
    }
  }
  if (velocity_valid_) {
    *predicted = pose_ * Pose2D(velocity_.x() * dt, velocity_.y() * dt, velocity_.z() * dt);
    return PredictionSource::kConstantVelocity;
  }
  *predicted = pose_;
  return PredictionSource::kNone;
}

void OdometryTracker::setKeyframe(const Scan& scan, const Pose2D& pose,
                                  const Eigen::Matrix3d& covariance) {
  matcher_.setReference(scan);
  has_keyframe_ = matcher_.hasReference();
  keyframe_requested_ = false;
  keyframe_pose_ = pose;
  keyframe_covariance_ = covariance;
  keyframe_beam_count_ = scan.beam_count;
  ++keyframe_id_;
}

TrackerUpdate OdometryTracker::processScan(double stamp, const Scan& sensor_scan,
                                           std::vector<Pose2D>* population_out) {
  TrackerUpdate update;
  update.stamp = stamp;
  if (population_out) population_out->clear();
  if (!std::isfinite(stamp)) {
    update.warning = "scan stamp is not finite; scan ignored";
    update.pose = pose_;
    update.pose_covariance = pose_covariance_;
    return update;
  }

  if (initialised_) {
    const double dt = stamp - last_stamp_;
    if (dt < 0.0 || dt > options_.max_time_jump) {
      std::ostringstream text;
      text << "scan time " << (dt < 0.0 ? "went back" : "jumped forward") << " by " << std::abs(dt)
           << " s; odometry reset to the origin";
      update.warning = text.str();
      reset();
      // Back in time, the odometry history is of another timeline (a looped bag, a clock reset): mixed with
      // the new samples at the same stamps it would turn every prediction into a jump.
      if (dt < 0.0) odometry_.clear();
    }
  }

  // A sweep taken while moving is sheared (the last beam is milliseconds younger than the first), and a
  // match reads the shear as a small turn of one sign per metre: on fr079 it added up to ~25 degrees.
  Scan compensated;
  const bool deskew = options_.deskew && initialised_ && velocity_valid_ && sensor_scan.hasBeamTimes();
  if (deskew) compensated = deskewScan(sensor_scan, laserVelocity(laser_mount_, velocity_));
  const Scan& scan = deskew ? compensated : sensor_scan;
  update.deskewed = deskew;

  const bool usable = static_cast<int>(scan.size()) >= options_.min_points;
  if (!initialised_) {
    initialised_ = true;
    last_stamp_ = stamp;
    history_.push_back(StampedPose{stamp, pose_});
    update.reset = true;
    update.published = true;
    update.pose = pose_;
    update.pose_covariance = pose_covariance_;
    if (usable) {
      setKeyframe(scan, pose_, pose_covariance_);
      update.new_keyframe = true;
      update.table_build_ms = matcher_.lastTableBuildMs();
    }
    update.keyframe_id = keyframe_id_;
    return update;
  }

  Pose2D predicted;
  std::string prediction_warning;
  update.prediction = predict(stamp, &predicted, &prediction_warning);
  if (update.warning.empty()) update.warning = prediction_warning;
  update.guess = predicted;
  const Pose2D predicted_step = relativePose(pose_, predicted);

  Pose2D new_pose = predicted;
  Eigen::Matrix3d new_covariance =
      composeCovariance(pose_, pose_covariance_, predicted_step, odometryNoise(options_, predicted_step));
  Eigen::Matrix3d step_covariance = odometryNoise(options_, predicted_step) * options_.fallback_covariance_scale;

  if (has_keyframe_ && usable) {
    // Guess of the new laser pose in the keyframe's laser frame: conjugate the base motion by the mount.
    const Pose2D base_motion = relativePose(keyframe_pose_, predicted);
    const Pose2D laser_guess = laser_mount_.inverse() * base_motion * laser_mount_;
    std::vector<Pose2D>* population = population_out;
    update.match = matcher_.match(scan, laser_guess, population);
    update.matched = true;
    guardAgainstJump(scan, laser_guess, update.prediction, &update);
    const bool fits = update.match.fitness_ratio >= options_.min_fitness && update.match.pose.isFinite();
    const bool match_ok = (update.match.status == MatchStatus::kOk ||
                           update.match.status == MatchStatus::kMbicpNotConverged) && fits;
    // Degenerate geometry (a featureless corridor): the scan still fixes some directions; its covariance
    // carries the maximum variance along the others, where the prediction decides.
    const bool degenerate = update.match.status == MatchStatus::kMbicpFailed &&
                            update.match.mbicp_status == MbicpStatus::kDegenerate && fits &&
                            update.match.covariance.allFinite();
    if (match_ok) {
      recent_fitness_ = recent_fitness_ > 0.0 ? 0.8 * recent_fitness_ + 0.2 * update.match.fitness_ratio
                                              : update.match.fitness_ratio;
      const Pose2D base_estimate = laser_mount_ * update.match.pose * laser_mount_.inverse();
      const Eigen::Matrix3d base_cov = laserToBaseCovariance(laser_mount_, update.match.pose, update.match.covariance);
      new_pose = keyframe_pose_ * base_estimate;
      new_covariance = composeCovariance(keyframe_pose_, keyframe_covariance_, base_estimate, base_cov);
      step_covariance = base_cov;
    } else if (degenerate) {
      const Pose2D base_estimate = laser_mount_ * update.match.pose * laser_mount_.inverse();
      const Eigen::Matrix3d base_cov = laserToBaseCovariance(laser_mount_, update.match.pose, update.match.covariance);
      Eigen::Matrix3d fused_cov;
      const Pose2D fused =
          fuseWithPrediction(base_estimate, base_cov, base_motion, odometryNoise(options_, base_motion), &fused_cov);
      if (fused.isFinite() && fused_cov.allFinite()) {
        new_pose = keyframe_pose_ * fused;
        new_covariance = composeCovariance(keyframe_pose_, keyframe_covariance_, fused, fused_cov);
        step_covariance = fused_cov;
      } else {
        update.fallback = true;
      }
    } else {
      update.fallback = true;
    }
    if (population_out) {
      for (auto& pose : *population_out) pose = keyframe_pose_ * (laser_mount_ * pose * laser_mount_.inverse());
    }
  } else {
    update.fallback = true;  // nothing to match against (or nothing to match): keep the motion predicted
    update.match.status = has_keyframe_ ? MatchStatus::kTooFewPoints : MatchStatus::kNoReference;
  }
  if (update.fallback) new_covariance += step_covariance;

  // Velocity over a baseline of at least kVelocityBaseline seconds, capped at the plausible speeds.
  history_.push_back(StampedPose{stamp, new_pose});
  while (history_.size() > 2 && stamp - history_[1].stamp >= kVelocityBaseline) history_.pop_front();
  const double baseline = stamp - history_.front().stamp;
  if (baseline >= kVelocityBaseline && baseline <= kMaxVelocityAge) {
    const Pose2D motion = relativePose(history_.front().pose, new_pose);
    Eigen::Vector3d velocity(motion.x / baseline, motion.y / baseline, motion.theta / baseline);
    const double speed = velocity.head<2>().norm();
    if (speed > options_.max_odometry_speed) velocity.head<2>() *= options_.max_odometry_speed / speed;
    velocity.z() = std::clamp(velocity.z(), -options_.max_odometry_turn_rate, options_.max_odometry_turn_rate);
    velocity_ = velocity;
    velocity_valid_ = true;
    update.velocity_covariance =
        (step_covariance / (baseline * baseline)).cwiseMin(kMaxVariance).cwiseMax(-kMaxVariance);
  } else {
    if (baseline > kMaxVelocityAge) velocity_valid_ = false;
    update.velocity_covariance = Eigen::Matrix3d::Identity() * kMaxVariance;
  }

  pose_ = new_pose;
  pose_covariance_ = new_covariance;
  last_stamp_ = stamp;

  // A new reference when the robot has moved away from the keyframe, when the match was poor or failed
  // (the old reference no longer explains the scene), or when the scanner changed.
  const Pose2D since_keyframe = relativePose(keyframe_pose_, pose_);
  // Only a usable scan can become the new keyframe (an empty scan has no geometry): warn when it does.
  const bool geometry_changed = has_keyframe_ && usable && scan.beam_count != keyframe_beam_count_;
  if (geometry_changed && update.warning.empty()) {
    update.warning = "scan beam count changed from " + std::to_string(keyframe_beam_count_) + " to " +
                     std::to_string(scan.beam_count) + "; new keyframe";
  }
  const bool wants_keyframe = !has_keyframe_ || keyframe_requested_ || geometry_changed || update.fallback ||
                              since_keyframe.translationNorm() > options_.keyframe_distance ||
                              std::abs(since_keyframe.theta) > options_.keyframe_angle ||
                              (update.matched && update.match.fitness_ratio < options_.keyframe_min_fitness);
  if (wants_keyframe && usable) {
    setKeyframe(scan, pose_, pose_covariance_);
    update.new_keyframe = true;
    update.table_build_ms = matcher_.lastTableBuildMs();
  }

  update.published = true;
  update.pose = pose_;
  update.pose_covariance = pose_covariance_;
  update.velocity = velocity_;
  update.keyframe_id = keyframe_id_;
  return update;
}

}  // namespace hglasm
