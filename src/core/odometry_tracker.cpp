#include "hglasm_odometry/core/odometry_tracker.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

#include "hglasm_odometry/core/deskew.h"
#include "hglasm_odometry/core/timing.h"

namespace hglasm {

std::string inconsistency(const TrackerOptions& options, const std::string& prefix) {
  for (const std::string& error :
       {inconsistency(options.matcher.genetic, prefix), inconsistency(options.learning.noise, prefix),
        inconsistency(options.conversion, prefix)}) {
    if (!error.empty()) return error;
  }
  return "";
}
namespace {

bool matchUsable(const MatchResult& match) {
  return (match.status == MatchStatus::kOk || match.status == MatchStatus::kMbicpNotConverged) &&
         match.pose.isFinite();
}

}  // namespace

OdometryTracker::OdometryTracker(const TrackerOptions& options)
    : options_(options),
      matcher_(options.matcher),
      local_map_(options.local_map, mapTables(options.matcher)),
      extrapolator_(options.prediction),
      learner_(options.learning, options.motion, options.prediction.imu),
      leap_detector_(options.leap),
      fitness_(options.leap.max_mahalanobis),
      keyframes_(options.keyframe) {
  extrapolator_.setOdometryTimeOffset(learner_.odometryTimeOffset().offset());
}

void OdometryTracker::setLaserMount(const Pose2D& base_to_laser) {
  if (!base_to_laser.isFinite()) return;
  laser_mount_ = base_to_laser;
  learner_.setLaserMount(base_to_laser);
}

void OdometryTracker::reset() {
  initialised_ = false;
  local_map_.clear();
  pose_ = publishedToInternal(Pose2D());  // published at the origin
  pose_covariance_.setZero();
  map_covariance_.setZero();
  extrapolator_.reset();
  leap_detector_.reset();
  fitness_.reset();
  learner_.restart();
  keyframes_.restart();
  set_pose_stamp_.reset();
  unconfirmed_since_.reset();
}

bool OdometryTracker::setPose(double stamp, const Pose2D& pose, const Eigen::Matrix3d& covariance) {
  if (!std::isfinite(stamp) || !pose.isFinite() || !isValidPoseCovariance(covariance)) return false;
  reset();
  pose_ = publishedToInternal(Pose2D(pose.x, pose.y, normalizeAngle(pose.theta)));
  pose_covariance_ = symmetricClamped(covariance);
  set_pose_stamp_ = stamp;
  return true;
}

TrackerUpdate OdometryTracker::processScan(double stamp, const Scan& sensor_scan,
                                           std::vector<Pose2D>* population_out) {
  TrackerUpdate update;
  update.stamp = stamp;
  if (population_out) population_out->clear();
  if (refuse(stamp, &update)) return update;
  TrackerDiagnostics& diagnostics = update.diagnostics;
  diagnostics.odometry_time_offset = learner_.odometryTimeOffset().offset();  // the one predict() reads with
  diagnostics.odometry_time_offset_estimate = learner_.odometryTimeOffset().estimate();

  Scan compensated;
  diagnostics.deskewed = deskew(stamp, sensor_scan, &compensated);
  const Scan& scan = diagnostics.deskewed ? compensated : sensor_scan;
  const bool usable = static_cast<int>(scan.size()) >= options_.min_points;
  if (!initialised_) {
    initialise(stamp, scan, usable, &update);
    return update;
  }

  const MotionPrediction prediction = predict(stamp, &update);
  Estimate estimate;
  bool matched = false;
  if (!local_map_.empty() && usable) {
    update.matched = true;
    diagnostics.map_keyframes = static_cast<int>(local_map_.keyframeCount());
    matched = matchScan(scan, prediction, population_out, &update, &estimate);
    if (matched && !update.leap && learner_.lastScanUsable()) learnTimeOffset(stamp);
  } else {
    diagnostics.match.status = local_map_.empty() ? MatchStatus::kNoReference : MatchStatus::kTooFewPoints;
  }
  if (!matched) {
    learner_.addUnmatchedScan();
    update.fallback = true;  // nothing (convincing) to match: keep the motion predicted
    estimate = integratePrediction(prediction);
    if (usable) diagnostics.fitness_ratio = judge(scan).fitnessRatio(estimate.laser_in_map);
    // A velocity's guess (intel's wheels arriving late) can be far off in a turn; once the wheels cover
    // the span, they predict from the last pose a scan or the wheels stood behind, not from the guess.
    if (prediction.source == PredictionSource::kOdometry) {
      unconfirmed_since_.reset();
    } else if (!unconfirmed_since_) {
      unconfirmed_since_ = Anchor{last_stamp_, pose_};
    }
  } else {
    unconfirmed_since_.reset();
  }
  advance(stamp, estimate, &update);
  updateMap(scan, usable, &update);
  publish(&update);
  return update;
}

bool OdometryTracker::refuse(double stamp, TrackerUpdate* update) const {
  if (std::isfinite(stamp) && !(initialised_ && stamp < last_stamp_)) return false;
  if (std::isfinite(stamp)) {
    std::ostringstream text;
    text << "scan stamped " << last_stamp_ - stamp << " s before the last one processed; dropped";
    update->warning = text.str();
    update->stale = true;
  } else {
    update->warning = "scan stamp is not finite; scan ignored";
  }
  publishPose(update);
  return true;
}

bool OdometryTracker::deskew(double stamp, const Scan& sensor_scan, Scan* compensated) const {
  if (!options_.deskew || !initialised_) return false;
  SweepMotion motion;
  if (extrapolator_.velocityKnown()) motion.base_velocity = extrapolator_.velocity();
  if (options_.prediction.use_imu) {
    motion.base_rotation = [this](double from, double to, double* angle) {
      return extrapolator_.imuRotation(from, to, angle);
    };
  }
  return deskewSweep(sensor_scan, stamp, mountInUse(), motion, compensated);
}

void OdometryTracker::initialise(double stamp, const Scan& scan, bool usable, TrackerUpdate* update) {
  initialised_ = true;
  last_stamp_ = stamp;
  if (set_pose_stamp_) advanceSetPose(stamp, update);
  extrapolator_.startNextPredictionAt(stamp, options_.learning.odometry_time_offset.max_offset);
  extrapolator_.addPose(stamp, pose_);
  update->reset = true;
  update->published = true;
  publishPose(update);
  if (usable) addKeyframe(scan, update);
  update->keyframe_id = keyframes_.keyframes();
  update->diagnostics.learned.wheel_noise = learner_.wheelNoise().scale();
}

void OdometryTracker::advanceSetPose(double stamp, TrackerUpdate* update) {
  const double from = *set_pose_stamp_;
  set_pose_stamp_.reset();
  if (!(stamp > from)) return;  // a scan at or before the pose's stamp starts from the pose as given
  std::string warning;
  const MotionPrediction motion = extrapolator_.predict(from, stamp, learner_.wheelNoise(), &warning);
  if (motion.source != PredictionSource::kOdometry) return;  // no wheel motion known: the pose as given
  pose_covariance_ = composeClamped(pose_, pose_covariance_, motion.motion, motion.covariance);
  pose_ = pose_ * motion.motion;
  update->diagnostics.guess = pose_;
  update->diagnostics.prediction = motion.source;
}

MotionPrediction OdometryTracker::predict(double stamp, TrackerUpdate* update) const {
  std::string warning;
  MotionPrediction prediction = extrapolator_.predict(last_stamp_, stamp, learner_.wheelNoise(), &warning);
  if (prediction.source == PredictionSource::kOdometry && unconfirmed_since_) {
    predictFromAnchor(stamp, &prediction);
  }
  if (update->warning.empty()) update->warning = warning;
  update->diagnostics.prediction = prediction.source;
  update->diagnostics.rotation_from_imu = prediction.rotation_from_imu;
  update->diagnostics.guess = pose_ * prediction.motion;
  return prediction;
}

void OdometryTracker::predictFromAnchor(double stamp, MotionPrediction* prediction) const {
  std::string warning;
  const MotionPrediction since =
      extrapolator_.predict(unconfirmed_since_->stamp, stamp, learner_.wheelNoise(), &warning);
  if (since.source != PredictionSource::kOdometry) return;
  // The same wheel motion, seen from the guessed pose: its covariance turns with the frame. wheel_motion
  // and dt stay the step's: after an unmatched scan the learners skip this step.
  const Pose2D frame_change(0.0, 0.0, unconfirmed_since_->pose.theta - pose_.theta);
  prediction->motion = relativePose(pose_, unconfirmed_since_->pose * since.motion);
  prediction->covariance = rotateCovariance(frame_change, since.covariance);
  prediction->nominal_covariance = rotateCovariance(frame_change, since.nominal_covariance);
  prediction->rotation_from_imu = since.rotation_from_imu;
}

OdometryTracker::Prior OdometryTracker::priorFor(const MotionPrediction& prediction) const {
  Prior prior;
  const Pose2D laser_previous = laserInMap(pose_);
  const Pose2D laser_motion = laserMotion(prediction.motion);
  const Eigen::Matrix3d zero = Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d previous_part = composeClamped(laser_previous, map_covariance_, laser_motion, zero);
  prior.motion_covariance =
      composeClamped(laser_previous, zero, laser_motion, laserMotionCovariance(prediction));
  // Without fusion the prediction only centres the search.
  prior.informative = options_.fusion && prediction.source != PredictionSource::kNone;
  prior.covariance = previous_part + prior.motion_covariance;
  if (!prior.informative) {
    // No motion known yet: flat over the preset's box.
    prior.covariance = boxVariances(options_.matcher.genetic.box, options_.search.sigmas).asDiagonal();
  }
  prior.mean = laser_previous * laser_motion;
  return prior;
}

void OdometryTracker::refineIfSlipped(const Scan& scan, const ScanJudge& scan_judge,
                                      const MotionPrediction& prediction, const LeapHypotheses& h,
                                      MatchCandidate* tight, TrackerDiagnostics* diagnostics) {
  const double weight = leap_detector_.slipWeight(*tight, h, prediction.motion);
  if (!(weight < options_.leap.slip_refine_below)) return;
  PosePrior softened = h.prior;
  softened.information *= weight;
  const MatchCandidate refined =
      candidate(scan_judge, matcher_.refine(scan, tight->match.pose, &softened), h.prior);
  if (!refined.acceptable || refined.fitness_ratio < tight->fitness_ratio) return;
  *tight = refined;
  diagnostics->prior_weight = weight;
}

bool OdometryTracker::matchScan(const Scan& scan, const MotionPrediction& prediction,
                                std::vector<Pose2D>* population_out, TrackerUpdate* update,
                                Estimate* estimate) {
  TrackerDiagnostics& diagnostics = update->diagnostics;
  const Prior prior = priorFor(prediction);
  const SearchEffort wide_search = effortOf(options_.matcher.genetic);  // the preset's whole box
  LeapHypotheses h = leap_detector_.hypotheses(prior.mean, prior.covariance,
                                               boxVariances(wide_search.box, options_.search.sigmas));
  h.map_frame = local_map_.frame();
  const ScanJudge& scan_judge = judge(scan);
  diagnostics.search =
      prior.informative ? searchAround(options_.matcher.genetic, options_.search, h.covariance) : wide_search;
  MatchCandidate tight = candidate(scan_judge,
                                   matcher_.match(scan, h.prior.mean, population_out, &diagnostics.search,
                                                  options_.fusion ? &h.prior : nullptr),
                                   h.prior);
  // A slip is the wheels': a constant velocity's guess has its own noise model and nothing that slips, and
  // an IMU's rotation does not slip with the wheels; those priors are left as predicted. (Wheels read a
  // little past their newest sample are still the wheels', their extrapolation's uncertainty added.)
  // Without fusion the match never had the prior.
  if (options_.fusion && prediction.source == PredictionSource::kOdometry && !prediction.rotation_from_imu) {
    refineIfSlipped(scan, scan_judge, prediction, h, &tight, &diagnostics);
  }
  // A prediction in doubt: the preset's whole box is searched under the second hypothesis.
  std::vector<Pose2D> wide_population;
  std::function<MatchCandidate()> search_wide;
  if (prior.informative && leap_detector_.inDoubt(tight, h, fitness_)) {
    search_wide = [&] {
      const MatchResult match = matcher_.match(
          scan, h.prior.mean, population_out ? &wide_population : nullptr, &wide_search, &h.wide_prior);
      return candidate(scan_judge, match, h.prior);
    };
  }
  const LeapVerdict verdict = leap_detector_.test(scan_judge, h, prior.informative, tight, search_wide,
                                                  !prediction.rotation_from_imu);
  leap_detector_.remember(verdict, tight.acceptable && fitness_.usual(tight.fitness_ratio));
  if (verdict.wide) {
    diagnostics.search = wide_search;
    if (population_out) *population_out = wide_population;
  }
  record(verdict, update);
  if (population_out) {
    for (auto& pose : *population_out) pose = baseInOdometry(pose);
  }
  const MatchCandidate& chosen = verdict.chosen;
  if (!chosen.acceptable) return false;
  diagnostics.fitness_ratio = chosen.fitness_ratio;
  diagnostics.fits_as_usual = fitness_.usual(chosen.fitness_ratio);
  // A scan whose leap waits for confirmation fits poorly where it stays: not a usual fit.
  if (!verdict.deferred) fitness_.add(chosen.fitness_ratio);
  *estimate = estimateFrom(chosen, prior);
  // After a leap (or a deferred one) the wheels were wrong beyond their noise: an outlier, not their noise.
  learner_.addMatchedScan(prediction, last_stamp_, scanOnlyPose(chosen.match),
                          !update->leap && !verdict.deferred);
  applyLearnedModels();
  moveMountTowardsLearned();
  return true;
}

void OdometryTracker::record(const LeapVerdict& verdict, TrackerUpdate* update) const {
  TrackerDiagnostics& diagnostics = update->diagnostics;
  update->leap = verdict.leapt;
  diagnostics.prediction_doubted = verdict.doubted;
  diagnostics.jump_rejected = verdict.rejected;
  diagnostics.leap_deferred = verdict.deferred;
  diagnostics.deferred_leap_fits_as_usual = verdict.deferred && fitness_.usual(verdict.wide_fitness_ratio);
  diagnostics.leap_probability = verdict.wrong_probability;
  const MatchResult& match = verdict.chosen.match;
  diagnostics.match = match;
  diagnostics.prior_mahalanobis = std::sqrt(verdict.chosen.mahalanobis_sq);
  diagnostics.degeneracy = match.scan_directions.degeneracy();
  diagnostics.weakest_direction = match.scan_directions.weakestDirection();
}

const ScanJudge& OdometryTracker::judge(const Scan& scan) {
  // The scan's likelihood counts its independent points only, as its information does, and is tempered
  // by as much as the learned noise says the scan overstates its information.
  const double weight =
      likelihoodWeight(options_.matcher.mbicp.independent_points, scan.size(), learner_.scanEvidenceScale());
  scan_judge_.reset(judgingTable(local_map_), scan, weight, options_.leap.likelihood_outlier);
  return scan_judge_;
}

MatchCandidate OdometryTracker::candidate(const ScanJudge& judge, const MatchResult& match,
                                          const PosePrior& prior) const {
  MatchCandidate candidate;
  candidate.match = match;
  const Eigen::Vector3d offset = poseDifference(match.pose, prior.mean);
  candidate.mahalanobis_sq = match.pose.isFinite() ? offset.dot(prior.information * offset) : 0.0;
  candidate.fitness_ratio = match.pose.isFinite() ? judge.fitnessRatio(match.pose) : 0.0;
  candidate.acceptable = matchUsable(match) && candidate.fitness_ratio >= options_.min_fitness;
  return candidate;
}

OdometryTracker::Estimate OdometryTracker::estimateFrom(const MatchCandidate& chosen,
                                                        const Prior& prior) const {
  Estimate estimate;
  estimate.laser_in_map = chosen.match.pose;
  estimate.map_covariance = symmetricClamped(chosen.match.covariance);
  // The increment's uncertainty: the scan's information fused with the motion's noise alone (the previous
  // pose's uncertainty is the trajectory's, already counted): the scan decides where it constrains the
  // pose, the wheels where it does not (along a corridor).
  const Eigen::Matrix3d increment_in_map =
      prior.informative
          ? informationOf(chosen.match.scan_information + informationOf(prior.motion_covariance))
          : estimate.map_covariance;
  const Pose2D previous = pose_;
  const Eigen::Matrix3d to_increment = jacobianOf(
      [&](const Pose2D& laser) { return relativePose(previous, baseInOdometry(laser)); }, chosen.match.pose);
  estimate.increment_covariance =
      symmetricClamped(to_increment * increment_in_map * to_increment.transpose());
  return estimate;
}

OdometryTracker::Estimate OdometryTracker::integratePrediction(const MotionPrediction& prediction) const {
  Estimate estimate;
  const Pose2D laser_previous = laserInMap(pose_);
  const Pose2D laser_motion = laserMotion(prediction.motion);
  estimate.laser_in_map = laser_previous * laser_motion;
  estimate.map_covariance =
      composeClamped(laser_previous, map_covariance_, laser_motion, laserMotionCovariance(prediction));
  estimate.increment_covariance =
      symmetricClamped(prediction.covariance * options_.uncertainty.fallback_scale);
  return estimate;
}

ScanOnlyPose OdometryTracker::scanOnlyPose(const MatchResult& match) const {
  ScanOnlyPose scan_only;
  scan_only.pose = baseInOdometry(match.scan_only_pose);
  scan_only.laser = local_map_.frame() * match.scan_only_pose;
  scan_only.usable = !match.degenerate && scan_only.pose.isFinite();
  if (!scan_only.usable) return scan_only;
  const Eigen::Matrix3d to_base =
      jacobianOf([this](const Pose2D& laser) { return baseInOdometry(laser); }, match.scan_only_pose);
  const auto parts = covarianceByDirection(match.scan_directions, kUnknownVariance);
  for (int j = 0; j < 3; ++j) scan_only.covariance_parts[j] = to_base * parts[j] * to_base.transpose();
  return scan_only;
}

void OdometryTracker::learnTimeOffset(double stamp) {
  if (!options_.prediction.use_odometry) return;
  if (learner_.learnTimeOffset(stamp, extrapolator_.odometry())) applyLearnedModels();
}

void OdometryTracker::applyLearnedModels() {
  extrapolator_.setOdometryTimeOffset(learner_.odometryTimeOffset().offset());
  extrapolator_.setWheelCalibration(learner_.wheelCalibration());
  extrapolator_.setImuBias(learner_.imuBias().bias(), learner_.imuBias().variance());
  matcher_.setScanNoiseScale(learner_.scanNoiseScale());
}

void OdometryTracker::moveMountTowardsLearned() {
  const Eigen::Vector2d change = learner_.wheelCalibration().laserOffset() - applied_laser_offset_;
  const double length = change.norm();
  if (length > 0.0) applied_laser_offset_ += change * std::min(1.0, kMaxMountChange / length);
}

void OdometryTracker::advance(double stamp, Estimate estimate, TrackerUpdate* update) {
  const Pose2D new_pose = baseInOdometry(estimate.laser_in_map);
  // What the models leave out grows with time: measured against the relations of the Freiburg logs.
  const UncertaintyOptions& floor = options_.uncertainty;
  const double dt = std::max(0.0, stamp - last_stamp_);
  estimate.increment_covariance.diagonal() +=
      dt * Eigen::Vector3d(floor.unexplained_xy * floor.unexplained_xy,
                           floor.unexplained_xy * floor.unexplained_xy,
                           floor.unexplained_theta * floor.unexplained_theta);
  pose_covariance_ =
      composeClamped(pose_, pose_covariance_, relativePose(pose_, new_pose), estimate.increment_covariance);
  map_covariance_ = estimate.map_covariance;
  update->increment_covariance = estimate.increment_covariance;
  updateVelocity(stamp, new_pose, update);
  pose_ = new_pose;
  last_stamp_ = stamp;
  extrapolator_.startNextPredictionAt(stamp, options_.learning.odometry_time_offset.max_offset);
}

void OdometryTracker::updateVelocity(double stamp, const Pose2D& new_pose, TrackerUpdate* update) {
  // The velocity over the baseline's increments is uncertain by their uncertainty over its length.
  const double baseline = extrapolator_.addPose(stamp, new_pose);
  update->velocity_covariance = baseline > 0.0
                                    ? symmetricClamped(update->increment_covariance / (baseline * baseline))
                                    : Eigen::Matrix3d::Identity() * kUnknownVariance;
}

void OdometryTracker::updateMap(const Scan& scan, bool usable, TrackerUpdate* update) {
  KeyframeCandidate candidate;
  candidate.pose = pose_;
  candidate.usable = usable;
  candidate.leapt = update->leap;
  candidate.leap_deferred = update->diagnostics.leap_deferred;
  candidate.deferred_leap_fits_as_usual = update->diagnostics.deferred_leap_fits_as_usual;
  candidate.matched = update->matched;
  candidate.match_failed = update->fallback;
  candidate.fitness_ratio = update->diagnostics.fitness_ratio;
  candidate.fits_as_usual = update->diagnostics.fits_as_usual;
  candidate.turn_rate = extrapolator_.velocity().z();
  switch (keyframes_.decide(candidate, local_map_.empty())) {
    case KeyframeAction::kNone:
      return;
    case KeyframeAction::kRestartMap:
      local_map_.clear();
      update->diagnostics.reanchored = true;
      addKeyframe(scan, update);
      return;
    case KeyframeAction::kAdd:
      addKeyframe(scan, update);
      return;
  }
}

void OdometryTracker::addKeyframe(const Scan& scan, TrackerUpdate* update) {
  const bool had_map = !local_map_.empty();
  const Pose2D old_frame = local_map_.frame();
  const auto start = std::chrono::steady_clock::now();
  local_map_.add(pose_ * mountInUse(), scan.points);
  matcher_.useTables(&local_map_.table(kFineTable), &local_map_.table(kCoarseTable));
  matcher_.extendReference(local_map_.reference(), local_map_.unchangedScans());
  update->diagnostics.table_build_ms = millisecondsSince(start);
  update->new_keyframe = true;
  // The pose's uncertainty relative to the map stays; only the frame it is expressed in turns.
  map_covariance_ = had_map ? rotateCovariance(relativePose(local_map_.frame(), old_frame), map_covariance_)
                            : Eigen::Matrix3d::Zero();
  keyframes_.keyframeAdded(pose_);
}

void OdometryTracker::publish(TrackerUpdate* update) const {
  update->published = true;
  publishPose(update);
  // Twists and increments of the published frame: the wheels' moved by the lever arm d (v + w x d).
  const Eigen::Matrix3d lever = adjoint(leverArm().inverse());
  update->velocity = lever * extrapolator_.velocity();
  update->velocity_covariance = lever * update->velocity_covariance * lever.transpose();
  update->increment_covariance = lever * update->increment_covariance * lever.transpose();
  update->keyframe_id = keyframes_.keyframes();
  update->diagnostics.learned = learner_.learned();
}

Pose2D OdometryTracker::leverArm() const {
  return Pose2D(applied_laser_offset_.x(), applied_laser_offset_.y(), 0.0);
}

Pose2D OdometryTracker::pose() const { return pose_ * leverArm(); }

Pose2D OdometryTracker::publishedToInternal(const Pose2D& published) const {
  return published * leverArm().inverse();
}

void OdometryTracker::publishPose(TrackerUpdate* update) const {
  // Internally the base is the frame the wheels move (the laser at the mount in use); published, it is the
  // frame tf's stated mount defines, so that the laser's points land where the user's tf puts them.
  update->pose = pose();
  update->pose_covariance = composeCovariance(pose_, pose_covariance_, leverArm(), Eigen::Matrix3d::Zero());
}

Pose2D OdometryTracker::mountInUse() const {
  return Pose2D(laser_mount_.x + applied_laser_offset_.x(), laser_mount_.y + applied_laser_offset_.y(),
                laser_mount_.theta);
}

Pose2D OdometryTracker::laserMotion(const Pose2D& base_motion) const {
  const Pose2D mount = mountInUse();
  return mount.inverse() * base_motion * mount;
}

Eigen::Matrix3d OdometryTracker::laserMotionCovariance(const MotionPrediction& prediction) const {
  const Eigen::Matrix3d to_laser =
      jacobianOf([this](const Pose2D& motion) { return laserMotion(motion); }, prediction.motion);
  return to_laser * prediction.covariance * to_laser.transpose();
}

Pose2D OdometryTracker::laserInMap(const Pose2D& base_pose) const {
  return local_map_.frame().inverse() * base_pose * mountInUse();
}

Pose2D OdometryTracker::baseInOdometry(const Pose2D& laser_in_map) const {
  return local_map_.frame() * laser_in_map * mountInUse().inverse();
}

}  // namespace hglasm
