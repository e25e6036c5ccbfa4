#include "hglasm_odometry/core/odometry_tracker.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>

namespace hglasm {
namespace {

constexpr double kMaxVariance = kUnknownVariance;
constexpr int kMinFitnessHistory = 5;      // matches before the usual fit is known
constexpr double kFitnessHalfLife = 50.0;  // matches
// Variance of the rotation between where two consecutive scans alone put the base (rad^2): two matches
// against the same map share most of their error; (2 mrad)^2 leaves room for a keyframe change between.
constexpr double kScanRotationVariance = 0.002 * 0.002;
constexpr int kDeskewKnots = 16;  // the IMU's turn during a sweep, sampled this often (then linear)

Eigen::Matrix3d symmetricClamped(const Eigen::Matrix3d& covariance) {
  const Eigen::Matrix3d symmetric = 0.5 * (covariance + covariance.transpose());
  return symmetric.cwiseMin(kMaxVariance).cwiseMax(-kMaxVariance);
}

/// composeCovariance, kept finite.
Eigen::Matrix3d composeClamped(const Pose2D& a, const Eigen::Matrix3d& cov_a, const Pose2D& b,
                               const Eigen::Matrix3d& cov_b) {
  return symmetricClamped(composeCovariance(a, cov_a, b, cov_b));
}

/// d f / d x at x (x, y, theta coordinates, angles wrapped), by central differences: for the few
/// rigid-frame changes per scan whose Jacobians are tedious to write out (a laser mount's lever arm).
template <typename Function>
Eigen::Matrix3d jacobianOf(const Function& f, const Pose2D& x) {
  constexpr double kStep = 1e-6;
  Eigen::Matrix3d jacobian;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    delta[k] = kStep;
    const Pose2D plus = f(Pose2D(x.x + delta.x(), x.y + delta.y(), x.theta + delta.z()));
    const Pose2D minus = f(Pose2D(x.x - delta.x(), x.y - delta.y(), x.theta - delta.z()));
    jacobian.col(k) << (plus.x - minus.x) / (2 * kStep), (plus.y - minus.y) / (2 * kStep),
        normalizeAngle(plus.theta - minus.theta) / (2 * kStep);
  }
  return jacobian;
}

/// Covariance of a pose's coordinates after its frame is changed by the rigid motion `frame_change`.
Eigen::Matrix3d rotateCovariance(const Pose2D& frame_change, const Eigen::Matrix3d& covariance) {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  const double c = std::cos(frame_change.theta), s = std::sin(frame_change.theta);
  rotation.topLeftCorner<2, 2>() << c, -s, s, c;
  return symmetricClamped(rotation * covariance * rotation.transpose());
}

/// The laser's velocity (vx, vy, omega in the laser frame) from the base's (base frame): the lever arm
/// of the mount adds omega x t to the translation.
Eigen::Vector3d laserVelocity(const Pose2D& mount, const Eigen::Vector3d& base_velocity) {
  const double omega = base_velocity.z();
  const Eigen::Vector2d at_laser(base_velocity.x() - omega * mount.y, base_velocity.y() + omega * mount.x);
  const double c = std::cos(mount.theta), s = std::sin(mount.theta);
  return Eigen::Vector3d(c * at_laser.x() + s * at_laser.y(), -s * at_laser.x() + c * at_laser.y(), omega);
}

Eigen::Vector3d poseDifference(const Pose2D& a, const Pose2D& b) {
  return Eigen::Vector3d(a.x - b.x, a.y - b.y, normalizeAngle(a.theta - b.theta));
}

/// Inverse of a covariance that may be nearly singular in one direction (a prior's never is).
Eigen::Matrix3d informationOf(const Eigen::Matrix3d& covariance) {
  return (covariance + Eigen::Matrix3d::Identity() * 1e-12).inverse();
}

bool matchUsable(const MatchResult& match) {
  return (match.status == MatchStatus::kOk || match.status == MatchStatus::kMbicpNotConverged) &&
         match.pose.isFinite();
}

}  // namespace

bool isValidPoseCovariance(const Eigen::Matrix3d& covariance) {
  if (!covariance.allFinite()) return false;
  const double scale = 1.0 + covariance.cwiseAbs().maxCoeff();
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(0.5 * (covariance + covariance.transpose()),
                                                              Eigen::EigenvaluesOnly);
  return solver.eigenvalues().minCoeff() >= -1e-12 * scale;
}

void OdometryTracker::RunningStats::add(double value) {
  // Exponentially weighted mean and variance: the usual fit drifts with the scene.
  const double alpha =
      count == 0 ? 1.0 : std::max(1.0 / (count + 1), 1.0 - std::exp2(-1.0 / kFitnessHalfLife));
  const double delta = value - mean;
  mean += alpha * delta;
  variance = (1.0 - alpha) * (variance + alpha * delta * delta);
  ++count;
}

namespace {

/// Whether the matcher's fine table is the graded one that scans are judged on.
bool matcherHasGradedTable(Algorithm algorithm) {
  return algorithm == Algorithm::kHglasmG || algorithm == Algorithm::kGlasmG;
}

/// The lookup tables the local map keeps for the matcher: the GA's fine and coarse table (of the
/// algorithm's kind), then the graded table scans are judged on if the fine one is not it.
std::vector<LookupTableOptions> mapTables(const MatcherOptions& matcher) {
  const bool lookup_ga = usesGeneticStage(matcher.algorithm) && !usesPolarPairing(matcher.algorithm);
  const TableKind kind =
      matcherHasGradedTable(matcher.algorithm) || !lookup_ga ? TableKind::kGraded : TableKind::kBinary;
  LookupTableOptions fine = matcher.table, coarse = matcher.coarse_table, graded = matcher.table;
  fine.kind = coarse.kind = kind;
  graded.kind = TableKind::kGraded;
  if (!lookup_ga) return {graded};
  if (kind == TableKind::kGraded) return {fine, coarse};
  return {fine, coarse, graded};
}

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

OdometryTracker::OdometryTracker(const TrackerOptions& options)
    : options_(options),
      matcher_(options.matcher),
      extrapolator_(options.use_odometry, options.odometry_max_extrapolation, options.max_odometry_speed,
                    options.max_odometry_turn_rate, options.use_imu, options.imu),
      keyframes_(options.keyframe),
      noise_(options.motion),
      noise_learner_(options.noise_learning),
      calibration_(options.wheel_calibration),
      gyro_bias_(options.imu),
      time_offset_(options.odometry_time_offset),
      local_map_(options.local_map, mapTables(options.matcher)) {
  extrapolator_.setOdometryTimeOffset(time_offset_.offset());
}

void OdometryTracker::setLaserMount(const Pose2D& base_to_laser) {
  if (base_to_laser.isFinite()) laser_mount_ = base_to_laser;
}

void OdometryTracker::addOdometry(double stamp, const Pose2D& odom_pose) {
  extrapolator_.addOdometry(stamp, odom_pose);
}

void OdometryTracker::reset() {
  initialised_ = false;
  local_map_.clear();
  pose_ = Pose2D();
  pose_covariance_.setZero();
  map_covariance_.setZero();
  extrapolator_.reset();
  prediction_wrong_ = 0.0;
  fitness_ = RunningStats();
  have_scan_only_pose_ = have_scan_rotation_ = false;
  noise_learner_.breakChain();
  unexplained_scans_ = 0;
  set_pose_stamp_.reset();
}

bool OdometryTracker::setPose(double stamp, const Pose2D& pose, const Eigen::Matrix3d& covariance) {
  if (!std::isfinite(stamp) || !pose.isFinite() || !isValidPoseCovariance(covariance)) return false;
  reset();
  pose_ = Pose2D(pose.x, pose.y, normalizeAngle(pose.theta));
  pose_covariance_ = symmetricClamped(covariance);
  set_pose_stamp_ = stamp;
  return true;
}

void OdometryTracker::advanceSetPose(double stamp, TrackerUpdate* update) {
  const double from = *set_pose_stamp_;
  set_pose_stamp_.reset();
  if (!(stamp > from)) return;  // a scan at or before the pose's stamp starts from the pose as given
  std::string warning;
  const MotionPrediction motion = extrapolator_.predict(from, stamp, noise_, &warning);
  if (motion.source != PredictionSource::kOdometry) return;  // no wheel motion known: the pose as given
  pose_covariance_ = composeClamped(pose_, pose_covariance_, motion.motion, motion.covariance);
  pose_ = pose_ * motion.motion;
  update->guess = pose_;
  update->prediction = motion.source;
}

Pose2D OdometryTracker::toMap(const Pose2D& base_pose) const {
  return local_map_.frame().inverse() * base_pose * laser_mount_;
}

Pose2D OdometryTracker::fromMap(const Pose2D& laser_in_map) const {
  return local_map_.frame() * laser_in_map * laser_mount_.inverse();
}

SearchEffort OdometryTracker::searchEffort(const Eigen::Matrix3d& prior_covariance, bool have_prior) const {
  const GeneticOptions& configured = options_.matcher.genetic;
  SearchEffort effort = effortOf(configured);
  if (!have_prior) return effort;
  const auto half_width = [&](int axis, double minimum, double maximum) {
    const double sigma = std::sqrt(std::max(0.0, prior_covariance(axis, axis)));
    return std::clamp(options_.search_sigmas * sigma, std::min(minimum, maximum), maximum);
  };
  effort.box.half_x = half_width(0, options_.min_search_xy, configured.box.half_x);
  effort.box.half_y = half_width(1, options_.min_search_xy, configured.box.half_y);
  effort.box.half_theta = half_width(2, options_.min_search_theta, configured.box.half_theta);
  // The GA size of the smallest of the papers' presets whose box holds this one, capped by the configured
  // preset's (Table 1 grows box and GA together).
  for (Preset preset : {Preset::kSmall, Preset::kMedium}) {
    const GeneticOptions tier = presetOptions(preset).genetic;
    if (effort.box.half_x <= tier.box.half_x && effort.box.half_y <= tier.box.half_y &&
        effort.box.half_theta <= tier.box.half_theta) {
      effort.population = std::min(tier.population, configured.population);
      effort.generations = std::min(tier.generations, configured.generations);
      effort.runs = std::min(tier.runs, configured.runs);
      effort.coarse_generations = std::min(tier.coarse_generations, effort.generations);
      break;
    }
  }
  return effort;
}

OdometryTracker::Candidate OdometryTracker::evaluate(const Scan& scan, const MatchResult& match,
                                                     const PosePrior& prior) const {
  Candidate candidate;
  candidate.match = match;
  const Eigen::Vector3d offset = poseDifference(match.pose, prior.mean);
  candidate.mahalanobis_sq = match.pose.isFinite() ? offset.dot(prior.information * offset) : 0.0;
  candidate.fitness_ratio = match.pose.isFinite() ? fitnessRatioAt(scan, match.pose) : 0.0;
  candidate.acceptable = matchUsable(match) && candidate.fitness_ratio >= options_.min_fitness;
  return candidate;
}

bool OdometryTracker::fitsAsUsual(double fitness_ratio) const {
  return fitness_.count < kMinFitnessHistory ||
         fitness_ratio >= fitness_.mean - options_.max_mahalanobis * std::sqrt(fitness_.variance);
}

bool OdometryTracker::predictionInDoubt(const Candidate& tight, const PosePrior& prior,
                                        const Eigen::Matrix3d& prior_covariance) const {
  const double gate_sq = options_.max_mahalanobis * options_.max_mahalanobis;
  if (!tight.acceptable || tight.mahalanobis_sq > gate_sq) return true;
  // The scan fits the map far worse than scans usually do: the pose near the prediction is not its place.
  if (!fitsAsUsual(tight.fitness_ratio)) return true;
  // The innovation test: where the scan alone would put the pose, against the prediction, with both
  // uncertainties (directions the scan does not constrain carry no innovation).
  const Eigen::Vector3d innovation = poseDifference(tight.match.scan_only_pose, prior.mean);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(tight.match.scan_information);
  const Eigen::Vector3d eigenvalues = solver.eigenvalues();
  Eigen::Vector3d scan_variances;
  for (int i = 0; i < 3; ++i) {
    scan_variances[i] =
        eigenvalues[i] > 1e-6 * std::max(eigenvalues.maxCoeff(), 1e-12) ? 1.0 / eigenvalues[i] : kMaxVariance;
  }
  const Eigen::Matrix3d scan_covariance =
      solver.eigenvectors() * scan_variances.asDiagonal() * solver.eigenvectors().transpose();
  const Eigen::Matrix3d total = prior_covariance + scan_covariance;
  const double innovation_sq = innovation.dot(total.ldlt().solve(innovation));
  return !(innovation_sq <= gate_sq);
}

double OdometryTracker::likelihoodWeight(const Scan& scan) const {
  // The scan's likelihood counts its independent points only, as its information does, and is tempered
  // by as much as the learned noise says the scan overstates its information.
  const double independent = options_.matcher.mbicp.independent_points;
  const double weight =
      independent > 0.0 ? std::min(1.0, independent / std::max<double>(1.0, scan.size())) : 1.0;
  return weight / noise_learner_.scanEvidenceScale();
}

double OdometryTracker::scanLogLikelihood(const Scan& scan, const Pose2D& pose) const {
  const LookupTable& table = judgingTable();
  if (table.empty() || scan.empty()) return 0.0;
  FitnessPoints points;
  points.assign(scan.points);
  return likelihoodWeight(scan) * table.logLikelihood(points, pose, options_.likelihood_outlier);
}

double OdometryTracker::freeSpaceLogLikelihood(const Scan& scan, const Pose2D& pose) const {
  // A beam crosses free space up to its end: something in front of a mapped wall (people) is allowed, a
  // beam through the wall is not. Each such beam costs what an outlier point does.
  const LookupTable& table = judgingTable();
  if (table.empty() || scan.empty() || options_.likelihood_outlier <= 0.0) return 0.0;
  const int through = table.beamsThroughSurfaces(scan.points, pose, 3.0 * table.options().sigma);
  return likelihoodWeight(scan) * through * std::log(options_.likelihood_outlier);
}

double OdometryTracker::fitnessRatioAt(const Scan& scan, const Pose2D& pose) const {
  const LookupTable& table = judgingTable();
  if (table.empty() || scan.empty()) return 0.0;
  const double best = static_cast<double>(table.maxCellValue()) * static_cast<double>(scan.size());
  return table.fitness(scan.points, pose) / best;
}

double OdometryTracker::logPrior(const Pose2D& pose, const PosePrior& prior,
                                 const Eigen::Matrix3d& covariance) {
  const Eigen::Vector3d offset = poseDifference(pose, prior.mean);
  const double log_det = std::log(std::max((2.0 * M_PI * covariance).determinant(), 1e-300));
  return -0.5 * offset.dot(prior.information * offset) - 0.5 * log_det;
}

OdometryTracker::Hypotheses OdometryTracker::hypothesesFor(const MotionPrediction& prediction) const {
  // The prediction holds: the laser's predicted pose in the local map's frame, uncertain by the previous
  // estimate's uncertainty there plus the motion's noise.
  Hypotheses h;
  const Pose2D laser_previous = toMap(pose_);
  const auto to_laser_motion = [this](const Pose2D& base_motion) {
    return laser_mount_.inverse() * base_motion * laser_mount_;
  };
  const Pose2D laser_motion = to_laser_motion(prediction.motion);
  const Eigen::Matrix3d to_laser = jacobianOf(to_laser_motion, prediction.motion);
  const Eigen::Matrix3d zero = Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d previous_part = composeClamped(laser_previous, map_covariance_, laser_motion, zero);
  h.motion_covariance = composeClamped(laser_previous, zero, laser_motion,
                                       to_laser * prediction.covariance * to_laser.transpose());
  // Without fusion (an ablation: the match replaces the prediction) the prediction only centres the search.
  h.informative = options_.fusion && prediction.source != PredictionSource::kNone;
  h.covariance = previous_part + h.motion_covariance;
  const double sigmas_sq = options_.search_sigmas * options_.search_sigmas;
  if (!h.informative) {
    // No motion known yet: flat over the preset's box (its half-widths as search_sigmas sigma).
    const SearchBox& box = options_.matcher.genetic.box;
    h.covariance = Eigen::Vector3d(box.half_x, box.half_y, box.half_theta).cwiseAbs2().asDiagonal();
    h.covariance /= sigmas_sq;
  }
  h.prior.mean = laser_previous * laser_motion;
  h.prior.information = informationOf(h.covariance);
  // The prediction is wrong (wheel slip, a glitch, a kidnap): the pose can be anywhere in the preset's box.
  // The prior odds follow the last scan's: a prediction that was wrong tends to stay wrong for a while.
  h.wide_search = searchEffort(h.covariance, false);
  const SearchBox& wide_box = h.wide_search.box;
  h.wide_covariance = h.covariance;
  h.wide_covariance.diagonal() +=
      Eigen::Vector3d(wide_box.half_x, wide_box.half_y, wide_box.half_theta).cwiseAbs2() / sigmas_sq;
  h.wide_prior = PosePrior{h.prior.mean, informationOf(h.wide_covariance)};
  h.wrong_probability = std::clamp(
      (1.0 - prediction_wrong_) * options_.leap_probability + prediction_wrong_ * options_.leap_persistence,
      1e-12, 1.0 - 1e-12);
  return h;
}

void OdometryTracker::scoreHypotheses(const Scan& scan, const Hypotheses& h, const MatchResult& match,
                                      double* holds, double* wrong) const {
  // Each hypothesis' evidence for a match, in the Laplace approximation: the scan's likelihood at the pose,
  // the hypothesis' prior density there, and the volume of the posterior around it (a hypothesis that
  // leaves a direction to the scan, and the scan leaves it open too, loses no probability for it).
  const double likelihood = scanLogLikelihood(scan, match.pose);
  const auto log_volume = [&](const PosePrior& hypothesis) {
    const Eigen::Matrix3d posterior = informationOf(match.scan_information + hypothesis.information);
    return 0.5 * std::log(std::max((2.0 * M_PI * posterior).determinant(), 1e-300));
  };
  *holds = likelihood + logPrior(match.pose, h.prior, h.covariance) + log_volume(h.prior) +
           std::log1p(-h.wrong_probability);
  *wrong = likelihood + logPrior(match.pose, h.wide_prior, h.wide_covariance) + log_volume(h.wide_prior) +
           std::log(h.wrong_probability);
}

double OdometryTracker::predictionScore(const Scan& scan, const Hypotheses& h) const {
  // Nothing near the prediction fits: the alternative to a leap is the prediction itself with a scan that
  // says little there (an occluded or changed view), not nothing. Its posterior volume is the prior's.
  const double log_volume = 0.5 * std::log(std::max((2.0 * M_PI * h.covariance).determinant(), 1e-300));
  return scanLogLikelihood(scan, h.prior.mean) + freeSpaceLogLikelihood(scan, h.prior.mean) +
         logPrior(h.prior.mean, h.prior, h.covariance) + log_volume + std::log1p(-h.wrong_probability);
}

void OdometryTracker::testLeap(const Scan& scan, const Hypotheses& h, std::vector<Pose2D>* population_out,
                               Candidate* chosen, TrackerUpdate* update) {
  double holds = 0.0, wrong = 0.0;
  prediction_wrong_ = h.wrong_probability;
  if (h.informative && chosen->acceptable) {
    scoreHypotheses(scan, h, chosen->match, &holds, &wrong);
    prediction_wrong_ = 1.0 / (1.0 + std::exp(holds - wrong));
  }
  if (!h.informative || !usesGeneticStage(options_.matcher.algorithm) ||
      !predictionInDoubt(*chosen, h.prior, h.covariance)) {
    return;
  }
  // Search the preset's whole box under the second hypothesis; the matches compete by posterior.
  update->prediction_doubted = true;
  std::vector<Pose2D> wide_population;
  Candidate leap = evaluate(scan,
                            matcher_.match(scan, h.prior.mean, population_out ? &wide_population : nullptr,
                                           &h.wide_search, &h.wide_prior),
                            h.prior);
  // The competition adds the beams' free space, which the likelihood field leaves out: a scan occluded by
  // people fits the map better turned onto another corridor, with beams through its walls.
  const double stay_score = chosen->acceptable
                                ? std::max(holds, wrong) + freeSpaceLogLikelihood(scan, chosen->match.pose)
                                : predictionScore(scan, h);
  double leap_holds = -HUGE_VAL, leap_wrong = -HUGE_VAL;
  if (leap.acceptable) {
    scoreHypotheses(scan, h, leap.match, &leap_holds, &leap_wrong);
    const double free_space = freeSpaceLogLikelihood(scan, leap.match.pose);
    leap_holds += free_space;
    leap_wrong += free_space;
  }
  const bool leap_is_far = leap.mahalanobis_sq > options_.max_mahalanobis * options_.max_mahalanobis;
  Candidate* loser = &leap;
  const double leap_score = std::max(leap_holds, leap_wrong);
  if (leap_score > stay_score) {
    std::swap(*chosen, leap);
    update->leap = leap_is_far;
    update->search = h.wide_search;
    prediction_wrong_ = 1.0 / (1.0 + std::exp(leap_holds - leap_wrong));
    if (population_out) *population_out = wide_population;
  } else {
    update->jump_rejected = leap.acceptable && leap_is_far;
  }
  // Both searches cost time and evaluations.
  chosen->match.prealign_ms += loser->match.prealign_ms;
  chosen->match.refine_ms += loser->match.refine_ms;
  chosen->match.evaluations += loser->match.evaluations;
}

void OdometryTracker::estimateFrom(const Candidate& chosen, const Hypotheses& h, Estimate* estimate) const {
  estimate->laser_in_map = chosen.match.pose;
  estimate->map_covariance = symmetricClamped(chosen.match.covariance);
  // The increment's uncertainty: the scan's information fused with the motion's noise alone (the previous
  // pose's uncertainty is the trajectory's, already counted): the scan decides where it constrains the
  // pose, the wheels where it does not (along a corridor).
  const Eigen::Matrix3d increment_in_map =
      h.informative ? informationOf(chosen.match.scan_information + informationOf(h.motion_covariance))
                    : estimate->map_covariance;
  const Pose2D previous = pose_;
  const Eigen::Matrix3d to_increment = jacobianOf(
      [&](const Pose2D& laser) { return relativePose(previous, fromMap(laser)); }, chosen.match.pose);
  estimate->increment_covariance =
      symmetricClamped(to_increment * increment_in_map * to_increment.transpose());
}

bool OdometryTracker::matchScan(const Scan& scan, const MotionPrediction& prediction,
                                std::vector<Pose2D>* population_out, TrackerUpdate* update,
                                Estimate* estimate) {
  const Hypotheses h = hypothesesFor(prediction);
  update->search = searchEffort(h.covariance, h.informative);
  Candidate chosen = evaluate(scan,
                              matcher_.match(scan, h.prior.mean, population_out, &update->search,
                                             options_.fusion ? &h.prior : nullptr),
                              h.prior);
  testLeap(scan, h, population_out, &chosen, update);
  if (!chosen.acceptable) prediction_wrong_ = h.wrong_probability;
  update->leap_probability = prediction_wrong_;
  update->match = chosen.match;
  update->prior_mahalanobis = std::sqrt(chosen.mahalanobis_sq);
  update->degeneracy = chosen.match.scan_directions.degeneracy();
  update->weakest_direction = chosen.match.scan_directions.weakestDirection();
  if (population_out) {
    for (auto& pose : *population_out) pose = fromMap(pose);
  }
  if (!chosen.acceptable) return false;
  update->fitness_ratio = chosen.fitness_ratio;
  fitness_.add(chosen.fitness_ratio);
  estimateFrom(chosen, h, estimate);
  // After a leap the wheels were wrong beyond their noise: an outlier, not their noise. The gyro's bias
  // is still learned (its filter clips what it cannot explain): a bias far off makes leaps of its own.
  learnNoise(prediction, chosen.match, !update->leap);
  return true;
}

void OdometryTracker::learnCalibration(const MotionPrediction& prediction, const Pose2D& scan_motion,
                                       const Eigen::Matrix3d& scan_covariance) {
  // The step's innovation variance: the wheels' noise and both scans' (heading; along the track, the
  // larger translation variance of each: the direction of travel is unknown here).
  const Eigen::Matrix3d scans = scan_covariance + scan_only_covariance_;
  const double heading_variance = prediction.covariance(2, 2) + scans(2, 2);
  // The larger eigenvalue of the 2 x 2 translation block, in closed form.
  const Eigen::Matrix2d translation =
      prediction.covariance.topLeftCorner<2, 2>() + scans.topLeftCorner<2, 2>();
  const double half_trace = 0.5 * (translation(0, 0) + translation(1, 1));
  const double larger =
      half_trace + std::hypot(0.5 * (translation(0, 0) - translation(1, 1)), translation(0, 1));
  // An IMU gave the rotation: the wheels' turn says nothing about their heading errors.
  calibration_.learn(prediction.wheel_motion, scan_motion, prediction.gyro ? -1.0 : heading_variance, larger);
  extrapolator_.setWheelCalibration(calibration_);
}

NoiseSample OdometryTracker::noiseSample(const MotionPrediction& prediction, const MatchResult& match,
                                         const Pose2D& scan_only) const {
  NoiseSample sample;
  sample.scan_pose = scan_only;
  const Eigen::Matrix3d to_base =
      jacobianOf([this](const Pose2D& laser) { return fromMap(laser); }, match.scan_only_pose);
  const auto parts = covarianceByDirection(match.scan_directions, kMaxVariance);
  for (int j = 0; j < 3; ++j) sample.scan_covariance[j] = to_base * parts[j] * to_base.transpose();
  sample.wheel_motion = prediction.motion;
  // The nominal covariance's translation block scales with the wheels' translation noise, its heading
  // with their heading noise (zero where an IMU gave the rotation); the rest (the IMU's) is known.
  sample.wheel_xy = prediction.nominal_covariance;
  sample.wheel_xy.row(2).setZero();
  sample.wheel_xy.col(2).setZero();
  sample.wheel_theta(2, 2) = prediction.nominal_covariance(2, 2);
  sample.wheel_known =
      prediction.covariance - noise_.scale().xy * sample.wheel_xy - noise_.scale().theta * sample.wheel_theta;
  return sample;
}

void OdometryTracker::learnNoise(const MotionPrediction& prediction, const MatchResult& match,
                                 bool learn_wheels) {
  // Two consecutive scans matched against the same map share most of their error, so the motion between
  // where the scans alone put them measures the increment; against the wheels' it shows both noises.
  const Pose2D scan_only = fromMap(match.scan_only_pose);
  const bool scan_usable = !match.degenerate && scan_only.isFinite();
  const bool usable = learn_wheels && prediction.source == PredictionSource::kOdometry && scan_usable;
  Eigen::Matrix3d scan_covariance = Eigen::Matrix3d::Zero();
  if (usable) {
    if (!have_scan_only_pose_) noise_learner_.breakChain();
    const NoiseSample sample = noiseSample(prediction, match, scan_only);
    noise_learner_.add(sample);
    noise_.setScale(noise_learner_.wheelScale());
    matcher_.setScanNoiseScale(noise_learner_.scanScale());
    for (const Eigen::Matrix3d& part : sample.scan_covariance) scan_covariance += part;
    if (have_scan_only_pose_)
      learnCalibration(prediction, relativePose(scan_only_pose_, scan_only), scan_covariance);
  } else {
    noise_learner_.breakChain();
  }
  scan_only_covariance_ = scan_covariance;
  if (scan_usable && have_scan_rotation_ && prediction.gyro) {
    const Pose2D scan_motion = relativePose(scan_only_pose_, scan_only);
    if (gyro_bias_.update(prediction.motion.theta, scan_motion.theta, kScanRotationVariance, prediction.dt,
                          last_stamp_ + prediction.dt)) {
      extrapolator_.setGyroBias(gyro_bias_.bias(), gyro_bias_.variance());
    }
  }
  have_scan_only_pose_ = usable;
  have_scan_rotation_ = scan_usable;
  scan_only_pose_ = scan_only;
}

OdometryTracker::Estimate OdometryTracker::integratePrediction(const MotionPrediction& prediction) const {
  Estimate estimate;
  const Pose2D laser_previous = toMap(pose_);
  const Pose2D laser_motion = laser_mount_.inverse() * prediction.motion * laser_mount_;
  estimate.laser_in_map = laser_previous * laser_motion;
  const Eigen::Matrix3d to_laser =
      jacobianOf([this](const Pose2D& motion) { return laser_mount_.inverse() * motion * laser_mount_; },
                 prediction.motion);
  estimate.map_covariance = composeClamped(laser_previous, map_covariance_, laser_motion,
                                           to_laser * prediction.covariance * to_laser.transpose());
  estimate.increment_covariance =
      symmetricClamped(prediction.covariance * options_.fallback_covariance_scale);
  return estimate;
}

bool OdometryTracker::refuseStale(double stamp, TrackerUpdate* update) const {
  if (!initialised_ || !(stamp < last_stamp_)) return false;
  std::ostringstream text;
  text << "scan stamped " << last_stamp_ - stamp << " s before the last one processed; dropped";
  update->warning = text.str();
  update->stale = true;
  update->pose = pose_;
  update->pose_covariance = pose_covariance_;
  return true;
}

void OdometryTracker::learnTimeOffset(double stamp) {
  if (!options_.use_odometry) return;
  time_offset_.addScanPose(stamp, scan_only_pose_);
  const double before = time_offset_.offset();
  if (!time_offset_.update(extrapolator_.odometry())) return;
  extrapolator_.setOdometryTimeOffset(time_offset_.offset());
  // The wheels' noise was learned from predictions read at the wrong time: it was mostly the offset's.
  if (std::abs(time_offset_.offset() - before) >= TimeOffsetEstimator::kMinOffset) {
    noise_learner_.reset();
    calibration_.reset();
    extrapolator_.setWheelCalibration(calibration_);
    noise_.setScale(noise_learner_.wheelScale());
    matcher_.setScanNoiseScale(noise_learner_.scanScale());
  }
}

bool OdometryTracker::deskew(double stamp, const Scan& sensor_scan, Scan* compensated) const {
  if (!options_.deskew || !initialised_ || !sensor_scan.hasBeamTimes()) return false;
  const bool velocity_known = extrapolator_.velocityKnown();
  const Eigen::Vector3d velocity = velocity_known ? extrapolator_.velocity() : Eigen::Vector3d::Zero();
  // The IMU's turn at kDeskewKnots + 1 times over the sweep, interpolated between for each beam.
  const double sweep = (sensor_scan.beam_count - 1) * sensor_scan.time_increment;
  std::array<double, kDeskewKnots + 1> turned{};
  bool gyro = options_.use_imu && sensor_scan.beam_count > 1;
  for (int k = 1; gyro && k <= kDeskewKnots; ++k) {
    const double t = sweep * k / kDeskewKnots;
    double angle = 0.0;
    gyro = t >= 0.0 ? extrapolator_.gyroRotation(stamp, stamp + t, &angle)
                    : extrapolator_.gyroRotation(stamp + t, stamp, &angle);
    turned[k] = t >= 0.0 ? angle : -angle;
  }
  if (!gyro) {
    if (!velocity_known) return false;
    *compensated = deskewScan(sensor_scan, laserVelocity(laser_mount_, velocity));
    return true;
  }
  *compensated = deskewScan(sensor_scan, [&](double t) {
    const double knot = std::clamp(t / sweep * kDeskewKnots, 0.0, static_cast<double>(kDeskewKnots));
    const int below = std::min(static_cast<int>(knot), kDeskewKnots - 1);
    const double angle = turned[below] + (knot - below) * (turned[below + 1] - turned[below]);
    return laser_mount_.inverse() * Pose2D(velocity.x() * t, velocity.y() * t, angle) * laser_mount_;
  });
  return true;
}

void OdometryTracker::initialise(double stamp, const Scan& scan, bool usable, TrackerUpdate* update) {
  initialised_ = true;
  last_stamp_ = stamp;
  if (set_pose_stamp_) advanceSetPose(stamp, update);
  extrapolator_.startNextPredictionAt(stamp, options_.odometry_time_offset.max_offset);
  extrapolator_.addPose(stamp, pose_);
  update->reset = true;
  update->published = true;
  update->pose = pose_;
  update->pose_covariance = pose_covariance_;
  if (usable) {
    addKeyframe(scan);
    update->new_keyframe = true;
    update->table_build_ms = table_build_ms_;
  }
  update->keyframe_id = keyframe_id_;
}

void OdometryTracker::updateVelocity(double stamp, const Pose2D& new_pose, TrackerUpdate* update) {
  // The velocity over the baseline's increments is uncertain by their uncertainty over its length.
  const double baseline = extrapolator_.addPose(stamp, new_pose);
  update->velocity_covariance = baseline > 0.0
                                    ? symmetricClamped(update->increment_covariance / (baseline * baseline))
                                    : Eigen::Matrix3d::Identity() * kMaxVariance;
}

void OdometryTracker::addKeyframe(const Scan& scan) {
  const bool had_map = !local_map_.empty();
  const Pose2D old_frame = local_map_.frame();
  const auto start = std::chrono::steady_clock::now();
  local_map_.add(pose_ * laser_mount_, scan.points);
  if (local_map_.tableCount() >= 2) {
    matcher_.useTables(&local_map_.table(kFineTable), &local_map_.table(kCoarseTable));
  }
  matcher_.extendReference(local_map_.reference(), local_map_.unchangedScans());
  table_build_ms_ = millisecondsSince(start);
  // The pose's uncertainty relative to the map stays; only the frame it is expressed in turns.
  map_covariance_ = had_map ? rotateCovariance(relativePose(local_map_.frame(), old_frame), map_covariance_)
                            : Eigen::Matrix3d::Zero();
  keyframes_.keyframeAdded(pose_);
  ++keyframe_id_;
}

void OdometryTracker::updateKeyframe(const Scan& scan, bool usable, TrackerUpdate* update) {
  // A scan without geometry cannot become a keyframe, nor one that leapt (the wheels may be right after
  // all, and a keyframe at the leap would hold the map to it).
  if (!usable || update->leap) return;
  // A usable scan the map could not explain is an outlier (someone standing in front of the laser) and
  // stays out of the map; a second one in a row says the map no longer describes where the robot is (it
  // moved during a pause, the surroundings changed), so the map restarts from it, at the pose predicted.
  const bool failed = update->fallback && !local_map_.empty();
  const bool reanchor = failed && unexplained_scans_ >= 1;
  unexplained_scans_ = failed ? unexplained_scans_ + 1 : 0;
  if (failed && !reanchor) return;
  if (reanchor) {
    local_map_.clear();
    update->reanchored = true;
    unexplained_scans_ = 0;
  }
  if (local_map_.empty() ||
      keyframes_.wantsKeyframe(pose_, update->matched, update->fallback, update->fitness_ratio)) {
    addKeyframe(scan);
    update->new_keyframe = true;
    update->table_build_ms = table_build_ms_;
  }
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
  if (refuseStale(stamp, &update)) return update;
  update.odometry_time_offset = time_offset_.offset();  // the one this scan's prediction reads with
  update.odometry_time_offset_estimate = time_offset_.estimate();

  // A sweep taken while moving is sheared (the last beam is milliseconds younger than the first), and a
  // match reads the shear as a small turn of one sign per metre: on fr079 it added up to ~25 degrees.
  Scan compensated;
  update.deskewed = deskew(stamp, sensor_scan, &compensated);
  const Scan& scan = update.deskewed ? compensated : sensor_scan;
  const bool usable = static_cast<int>(scan.size()) >= options_.min_points;
  if (!initialised_) {
    initialise(stamp, scan, usable, &update);
    update.noise_scale = noise_.scale();
    return update;
  }

  std::string prediction_warning;
  const MotionPrediction prediction = extrapolator_.predict(last_stamp_, stamp, noise_, &prediction_warning);
  if (update.warning.empty()) update.warning = prediction_warning;
  update.prediction = prediction.source;
  update.rotation_from_imu = prediction.gyro;
  update.guess = pose_ * prediction.motion;

  Estimate estimate;
  bool matched = false;
  if (!local_map_.empty() && usable) {
    update.matched = true;
    update.map_keyframes = static_cast<int>(local_map_.keyframeCount());
    matched = matchScan(scan, prediction, population_out, &update, &estimate);
    if (matched && have_scan_rotation_ && !update.leap) learnTimeOffset(stamp);
  } else {
    update.match.status = local_map_.empty() ? MatchStatus::kNoReference : MatchStatus::kTooFewPoints;
  }
  if (!matched) {
    have_scan_only_pose_ = have_scan_rotation_ = false;
    update.fallback = true;  // nothing (convincing) to match: keep the motion predicted
    estimate = integratePrediction(prediction);
    if (usable) update.fitness_ratio = fitnessRatioAt(scan, estimate.laser_in_map);
  }
  const Pose2D new_pose = fromMap(estimate.laser_in_map);
  // What the models leave out (timing, the scans' distortion, the surfaces' own errors) grows with time:
  // measured against the relations of the Freiburg logs.
  const double dt = std::max(0.0, stamp - last_stamp_);
  estimate.increment_covariance.diagonal() +=
      dt * Eigen::Vector3d(options_.unexplained_xy * options_.unexplained_xy,
                           options_.unexplained_xy * options_.unexplained_xy,
                           options_.unexplained_theta * options_.unexplained_theta);
  pose_covariance_ =
      composeClamped(pose_, pose_covariance_, relativePose(pose_, new_pose), estimate.increment_covariance);
  map_covariance_ = estimate.map_covariance;
  update.increment_covariance = estimate.increment_covariance;
  updateVelocity(stamp, new_pose, &update);
  pose_ = new_pose;
  last_stamp_ = stamp;
  extrapolator_.startNextPredictionAt(stamp, options_.odometry_time_offset.max_offset);
  updateKeyframe(scan, usable, &update);

  update.published = true;
  update.pose = pose_;
  update.pose_covariance = pose_covariance_;
  update.velocity = extrapolator_.velocity();
  update.keyframe_id = keyframe_id_;
  update.noise_scale = noise_.scale();
  update.scan_noise_scale = noise_learner_.scanScale();
  update.wheel_turn_scale = calibration_.turnScale();
  update.wheel_heading_per_metre = calibration_.headingPerMetre();
  update.wheel_distance_scale = calibration_.distanceScale();
  update.imu_bias = gyro_bias_.bias();
  return update;
}

}  // namespace hglasm
