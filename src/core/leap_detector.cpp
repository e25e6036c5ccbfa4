#include "hglasm_odometry/core/leap_detector.h"

#include <Eigen/Cholesky>
#include <algorithm>

#include "hglasm_odometry/core/covariance.h"

namespace hglasm {
namespace {

double logPrior(const Pose2D& pose, const PosePrior& prior, const Eigen::Matrix3d& covariance) {
  return logNormalDensity(poseDifference(pose, prior.mean), prior.information, covariance);
}

/// Squared Mahalanobis distance of where the scan alone would put the pose from the prediction, in their
/// summed covariance plus `extra` (directions the scan does not constrain carry no innovation).
double scanInnovationSq(const MatchCandidate& tight, const LeapHypotheses& h, const Eigen::Matrix3d& extra) {
  const Eigen::Vector3d innovation = poseDifference(tight.match.scan_only_pose, h.prior.mean);
  const Eigen::Matrix3d total = h.covariance + covarianceOfInformation(tight.match.scan_information) + extra;
  return innovation.dot(total.ldlt().solve(innovation));
}

}  // namespace

LeapDetector::LeapDetector(const LeapOptions& options) : options_(options) {}

void LeapDetector::remember(const LeapVerdict& verdict, bool scene_as_usual) {
  wrong_probability_ = verdict.wrong_probability;
  if (scene_as_usual) {
    const double keep = std::exp2(-1.0 / kFaultHalfLife);
    faults_ = keep * faults_ + ((verdict.leapt || verdict.deferred) ? 1.0 : 0.0);
    scans_ = keep * scans_ + 1.0;
  }
  pending_ = verdict.deferred;
  pending_correction_ = verdict.correction;
  pending_covariance_ = verdict.correction_covariance;
}

bool LeapDetector::confirms(const LeapVerdict& verdict, const LeapHypotheses& h) const {
  if (!pending_) return false;
  // The last scan's correction applied to this prediction, against this scan's match (the map's frame):
  // one slip of the wheels puts both at the same pose.
  const Pose2D expected = h.map_frame.inverse() * pending_correction_ * h.map_frame * h.prior.mean;
  const Pose2D matched = h.map_frame.inverse() * verdict.correction * h.map_frame * h.prior.mean;
  const Eigen::Vector3d offset(matched.x - expected.x, matched.y - expected.y,
                               normalizeAngle(matched.theta - expected.theta));
  const Eigen::Matrix3d covariance = pending_covariance_ + verdict.correction_covariance + h.covariance;
  const double mahalanobis_sq = offset.dot(covariance.ldlt().solve(offset));
  return mahalanobis_sq <= options_.max_mahalanobis * options_.max_mahalanobis;
}

double LeapDetector::wrongPrior() const {
  // A prediction that was wrong tends to stay wrong for a while.
  return std::clamp(
      (1.0 - wrong_probability_) * options_.probability + wrong_probability_ * options_.persistence, 1e-12,
      1.0 - 1e-12);
}

double LeapDetector::priorWeight(double innovation_sq) const {
  const double k = options_.slip_variance_scale;
  if (!(k > 1.0) || !std::isfinite(innovation_sq)) return 1.0;
  // Beyond the slip component's own gate: not a slip, a prediction that says nothing.
  if (innovation_sq > k * options_.max_mahalanobis * options_.max_mahalanobis) return 0.0;
  const double p = std::min(0.5, faultRate());
  // The two components' densities in 3 dimensions, relative to the first's at the innovation (no underflow).
  const double slip_odds =
      p / (1.0 - p) * std::pow(k, -1.5) * std::exp(0.5 * innovation_sq * (1.0 - 1.0 / k));
  const double slipped = std::isfinite(slip_odds) ? slip_odds / (1.0 + slip_odds) : 1.0;
  return 1.0 - slipped + slipped / k;
}

double LeapDetector::slipWeight(const MatchCandidate& tight, const LeapHypotheses& h,
                                const Pose2D& motion) const {
  if (!tight.acceptable) return 1.0;
  return priorWeight(scanInnovationSq(tight, h, slipCovariance(motion)));
}

Eigen::Matrix3d LeapDetector::slipCovariance(const Pose2D& motion) const {
  // Isotropic in translation, so the same in the base's and the map's frame.
  const double mount_sq = options_.slip_mount_sigma * options_.slip_mount_sigma;
  const double translation = mount_sq * (2.0 - 2.0 * std::cos(motion.theta));
  return Eigen::Vector3d(translation, translation, 0.0).asDiagonal();
}

LeapHypotheses LeapDetector::hypotheses(const Pose2D& mean, const Eigen::Matrix3d& covariance,
                                        const Eigen::Vector3d& box_variances) const {
  LeapHypotheses h;
  h.covariance = covariance;
  h.prior.mean = mean;
  h.prior.information = informationOf(h.covariance);
  h.wide_covariance = h.covariance;
  h.wide_covariance.diagonal() += box_variances;
  h.wide_prior = PosePrior{h.prior.mean, informationOf(h.wide_covariance)};
  h.wrong_probability = wrongPrior();
  return h;
}

bool LeapDetector::inDoubt(const MatchCandidate& tight, const LeapHypotheses& h,
                           const FitnessMonitor& fitness) const {
  const double gate_sq = options_.max_mahalanobis * options_.max_mahalanobis;
  if (!tight.acceptable || tight.mahalanobis_sq > gate_sq) return true;
  // The scan fits the map far worse than scans usually do: the pose near the prediction is not its place.
  if (!fitness.usual(tight.fitness_ratio)) return true;
  return !(scanInnovationSq(tight, h, Eigen::Matrix3d::Zero()) <= gate_sq);
}

LogPosteriors LeapDetector::logPosteriors(const ScanJudge& judge, const LeapHypotheses& h,
                                          const MatchResult& match) const {
  const double likelihood = judge.logLikelihood(match.pose);
  const auto log_volume = [&](const PosePrior& hypothesis) {
    return 0.5 * logDet2Pi(informationOf(match.scan_information + hypothesis.information));
  };
  LogPosteriors posteriors;
  posteriors.prediction_holds = likelihood + logPrior(match.pose, h.prior, h.covariance) +
                                log_volume(h.prior) + std::log1p(-h.wrong_probability);
  posteriors.prediction_wrong = likelihood + logPrior(match.pose, h.wide_prior, h.wide_covariance) +
                                log_volume(h.wide_prior) + std::log(h.wrong_probability);
  return posteriors;
}

double LeapDetector::predictionLogPosterior(const ScanJudge& judge, const LeapHypotheses& h) const {
  // Its posterior volume is the prior's.
  const double log_volume = 0.5 * logDet2Pi(h.covariance);
  return judge.logLikelihood(h.prior.mean) + judge.freeSpaceLogLikelihood(h.prior.mean) +
         logPrior(h.prior.mean, h.prior, h.covariance) + log_volume + std::log1p(-h.wrong_probability);
}

LeapVerdict LeapDetector::test(const ScanJudge& judge, const LeapHypotheses& h, bool informative,
                               const MatchCandidate& tight,
                               const std::function<MatchCandidate()>& search_wide, bool may_defer) const {
  LeapVerdict verdict;
  verdict.chosen = tight;
  verdict.wrong_probability = h.wrong_probability;
  LogPosteriors stay;
  if (informative && tight.acceptable) {
    stay = logPosteriors(judge, h, tight.match);
    verdict.wrong_probability = stay.wrongProbability();
  }
  if (search_wide) {
    verdict.doubted = true;
    const MatchCandidate wide = search_wide();
    verdict.wide_fitness_ratio = wide.fitness_ratio;
    const double stay_score = tight.acceptable ? stay.best() + judge.freeSpaceLogLikelihood(tight.match.pose)
                                               : predictionLogPosterior(judge, h);
    // The evidence is a Laplace approximation at the match: a far match whose MbICP was still moving when
    // it hit its iteration limit is no mode of the posterior, and cannot carry a leap.
    const bool settled = wide.match.status != MatchStatus::kMbicpNotConverged;
    LogPosteriors leap;
    if (wide.acceptable && (settled || !far(wide))) {
      leap = logPosteriors(judge, h, wide.match);
      leap.add(judge.freeSpaceLogLikelihood(wide.match.pose));
    }
    const MatchCandidate* loser = &wide;
    if (leap.best() > stay_score) {
      verdict.correction = h.map_frame * wide.match.pose * h.prior.mean.inverse() * h.map_frame.inverse();
      verdict.correction_covariance = wide.match.covariance;
      if (far(wide) && may_defer && confirmationRequired() && !confirms(verdict, h)) {
        verdict.deferred = true;  // the tight match stands until the next scan says the same
      } else {
        verdict.chosen = wide;
        verdict.wide = true;
        verdict.leapt = far(wide);
        verdict.wrong_probability = leap.wrongProbability();
        loser = &tight;
      }
    } else {
      verdict.rejected = wide.acceptable && far(wide);
    }
    // Both searches cost time and evaluations.
    verdict.chosen.match.prealign_ms += loser->match.prealign_ms;
    verdict.chosen.match.refine_ms += loser->match.refine_ms;
    verdict.chosen.match.evaluations += loser->match.evaluations;
  }
  if (!verdict.chosen.acceptable) verdict.wrong_probability = h.wrong_probability;
  return verdict;
}

}  // namespace hglasm
