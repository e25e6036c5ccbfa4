// Whether a scan's pose leaves the predicted motion: two hypotheses compete by posterior probability, "the
// prediction holds" (its prior) and "the prediction is wrong" (wheel slip, a glitch, a kidnap: a prior as
// wide as the preset's box). A leap needs the scan's evidence to outweigh the odds against it.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <functional>

#include "hglasm_odometry/core/fitness_monitor.h"
#include "hglasm_odometry/core/mbicp.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan_matcher.h"

namespace hglasm {

struct LeapOptions {
  /// The prediction is in doubt when the match (or where the scan alone would put the pose) lies farther
  /// from it than this Mahalanobis distance (3 degrees of freedom), or the scan fits the map this many
  /// standard deviations worse than matches usually do. Then the preset's whole box is searched too.
  double max_mahalanobis = 4.0;
  /// Probability that a prediction is wrong beyond its noise model (prior odds of a leap per scan)...
  double probability = 1e-3;
  /// ... and that it stays wrong at the next scan once it was (wheels slip in bursts, a glitch lasts).
  double persistence = 0.5;
  /// Outlier share of the scan likelihood that weighs leaps: a point far from the map costs log(outlier).
  double likelihood_outlier = 0.1;
  /// Wheels that have rarely been wrong (leaps of scans that fit the map as usual near the prediction, in
  /// fewer than `confirm_below` of those scans, forgetting with a half-life of kFaultHalfLife scans; the
  /// count starts at that rate over kTrustScans scans) leap only once the next scan's wide search asks for
  /// the same correction of its prediction (within max_mahalanobis): wheels that slipped stay off by what
  /// they lost, while a scan that fits some other place (a changed scene, a view the map lacks, repeated
  /// structure) points elsewhere the next time. Wheels that are wrong more often, and rotations predicted by
  /// an IMU (whose bias the scans teach), are corrected at once.
  bool confirm = true;
  double confirm_below = 1e-3;  ///< the prior odds of a leap, as `probability`
  /// A moderate slip: the wheels' prediction is a mixture of their noise model and, with the probability
  /// their faults have shown (LeapDetector::faultRate), a component `slip_variance_scale` times wider. After
  /// the match, the prior's information is scaled by its expected precision under that mixture's posterior
  /// at the innovation; below `slip_refine_below` MbICP refines again under the softened prior, and the
  /// refinement is kept where the scan fits the map better there. An innovation beyond `max_mahalanobis`
  /// of the slip component itself is no slip but a prediction that says nothing (stale wheel samples, a
  /// stall): the refinement drops the prior (the leap test still weighs the match against the prediction).
  /// 0 turns it off.
  double slip_variance_scale = 9.0;
  double slip_refine_below = 0.9;
  /// The laser's place on the robot known to this standard deviation (m) in that test: it moves the laser's
  /// predicted step by (R(turn) - I) times its error, so a disagreement in a turn is not taken for a slip.
  double slip_mount_sigma = 0.1;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, LeapOptions* options) {
  visitor.positiveNumber("leap/max_mahalanobis", &options->max_mahalanobis);
  visitor.number("leap/probability", &options->probability, 0.0, 0.5, true);
  visitor.number("leap/persistence", &options->persistence, 0.0, 1.0, true);
  visitor.number("leap/likelihood_outlier", &options->likelihood_outlier, 0.0, 1.0, true);
  visitor.boolean("leap/confirm", &options->confirm);
  visitor.number("leap/confirm_below", &options->confirm_below, 0.0, 1.0, true);
  visitor.nonNegativeNumber("leap/slip_variance_scale", &options->slip_variance_scale);
  visitor.fraction("leap/slip_refine_below", &options->slip_refine_below);
  visitor.nonNegativeNumber("leap/slip_mount_sigma", &options->slip_mount_sigma);
}

/// The two hypotheses a scan is matched under, in the local map's frame (the laser's pose).
struct LeapHypotheses {
  PosePrior prior;  ///< the prediction holds
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  PosePrior wide_prior;  ///< the prediction is wrong: the pose anywhere in the preset's box
  Eigen::Matrix3d wide_covariance = Eigen::Matrix3d::Zero();
  double wrong_probability = 0.0;  ///< prior probability of the second
  Pose2D map_frame;  ///< the local map's frame in the odometry frame (where a correction is remembered)
};

/// A match and how well it explains the scan.
struct MatchCandidate {
  MatchResult match;
  double fitness_ratio = 0.0;   ///< of the scan at the match's pose
  bool acceptable = false;      ///< usable, and fits at least min_fitness
  double mahalanobis_sq = 0.0;  ///< from the prediction
};

/// The log posteriors (up to a common constant) of one match under the two hypotheses.
struct LogPosteriors {
  double prediction_holds = -HUGE_VAL;
  double prediction_wrong = -HUGE_VAL;
  double best() const { return std::max(prediction_holds, prediction_wrong); }
  /// Posterior probability that the prediction is wrong.
  double wrongProbability() const { return 1.0 / (1.0 + std::exp(prediction_holds - prediction_wrong)); }
  /// Both times a further likelihood of the match.
  void add(double log_likelihood) {
    prediction_holds += log_likelihood;
    prediction_wrong += log_likelihood;
  }
};

/// What the leap test made of one scan.
struct LeapVerdict {
  MatchCandidate chosen;            ///< the tight match, or the wide one if it won (costs of both summed)
  bool doubted = false;             ///< the prediction was in doubt: the preset's box was searched too
  bool wide = false;                ///< the wide search's match won
  bool leapt = false;               ///< ... and lies beyond max_mahalanobis of the prediction
  bool rejected = false;            ///< a wide match that far lacked the evidence: the prediction held
  bool deferred = false;            ///< a wide match that far won, but awaits the next scan's confirmation
  double wrong_probability = 0.0;   ///< posterior probability that the prediction was wrong
  double wide_fitness_ratio = 0.0;  ///< of the wide search's match (0 if the prediction was not doubted)
  /// The far wide match as a correction of the prediction, taken or deferred: match = correction *
  /// prediction in the odometry frame. Wheels that slipped stay off by the same one: it moves every later
  /// prediction (their increments are right again) onto the truth.
  Pose2D correction;
  Eigen::Matrix3d correction_covariance = Eigen::Matrix3d::Zero();
};

/// Its one piece of state is how likely the last scan's prediction was wrong: the next scan's prior odds
/// follow it. Not thread-safe per instance.
class LeapDetector {
 public:
  explicit LeapDetector(const LeapOptions& options = {});

  /// The hypotheses for the laser's predicted pose `mean` with `covariance`; a wrong prediction widens it
  /// by `box_variances` (boxVariances of the preset's box).
  LeapHypotheses hypotheses(const Pose2D& mean, const Eigen::Matrix3d& covariance,
                            const Eigen::Vector3d& box_variances) const;

  /// Whether the prediction is in doubt after the `tight` match near it: the match, or where the scan alone
  /// would put the pose, lies beyond max_mahalanobis (both uncertainties counted; directions the scan does
  /// not constrain carry no innovation), nothing acceptable fits, or it fits worse than usual.
  bool inDoubt(const MatchCandidate& tight, const LeapHypotheses& h, const FitnessMonitor& fitness) const;

  /// Each hypothesis' evidence for a match, in the Laplace approximation: the scan's likelihood at the pose,
  /// the hypothesis' prior density there, and the volume of the posterior around it (a hypothesis that
  /// leaves a direction to the scan, and the scan leaves it open too, loses no probability for it).
  LogPosteriors logPosteriors(const ScanJudge& judge, const LeapHypotheses& h,
                              const MatchResult& match) const;

  /// Log posterior of "the prediction holds" at the predicted pose itself, for when nothing near it is
  /// acceptable: a scan that says little there (an occluded or changed view), not nothing.
  double predictionLogPosterior(const ScanJudge& judge, const LeapHypotheses& h) const;

  /// The test of one scan: `tight` is the match near the prediction (under h.prior). If `search_wide` is
  /// given the prediction was in doubt: it searches the preset's box under the second hypothesis, and the
  /// two matches compete by posterior, with the beams' free space (which the likelihood field leaves out: a
  /// scan occluded by people fits the map better turned onto another corridor, with beams through its
  /// walls). A far wide match whose MbICP hit its iteration limit (kMbicpNotConverged) is no mode of the
  /// posterior, so its evidence cannot be weighed: it cannot leap. `informative`: the prior holds
  /// information (else no posterior is formed).
  /// `may_defer`: a far leap may wait for confirmation (LeapOptions::confirm; false for an IMU's rotation).
  LeapVerdict test(const ScanJudge& judge, const LeapHypotheses& h, bool informative,
                   const MatchCandidate& tight, const std::function<MatchCandidate()>& search_wide,
                   bool may_defer = true) const;

  /// The verdict on this scan: the next scan's prior follows its probability that the prediction was wrong,
  /// and a deferred leap waits for the next scan to confirm it. `scene_as_usual`: the match near the
  /// prediction fit the map as scans usually do, so a far leap was the wheels' fault, not the scene's.
  void remember(const LeapVerdict& verdict, bool scene_as_usual);
  /// How often the wheels have been wrong beyond their noise (far leaps per scan that fit as usual), so far.
  double faultRate() const {
    return (options_.confirm_below * kTrustScans + faults_) / (kTrustScans + scans_);
  }
  /// The scale of the wheels' prior information after a match whose innovation lies at squared
  /// Mahalanobis distance `innovation_sq` (in the wheels', the scan's and slipCovariance()'s summed
  /// covariance): 1 - w + w / k for the posterior probability w of the slip component (k times the variance,
  /// probability faultRate(); LeapOptions::slip_variance_scale); 0 beyond max_mahalanobis of that
  /// component. 1 when slips are off.
  double priorWeight(double innovation_sq) const;
  /// priorWeight() for the match `tight` near the prediction of `h` (a base motion `motion`): where the scan
  /// alone would put the pose against the prediction; 1 without an acceptable match.
  double slipWeight(const MatchCandidate& tight, const LeapHypotheses& h, const Pose2D& motion) const;
  /// The innovation covariance's part for what the wheels' model leaves out (LeapOptions::slip_mount_sigma)
  /// for a predicted base motion `motion`.
  Eigen::Matrix3d slipCovariance(const Pose2D& motion) const;
  /// Whether a far leap waits for the next scan's confirmation (LeapOptions::confirm).
  bool confirmationRequired() const { return options_.confirm && faultRate() < options_.confirm_below; }
  static constexpr double kFaultHalfLife = 2000.0;  // scans
  static constexpr double kTrustScans = 1000.0;
  /// The prior probability that the prediction of the coming scan is wrong.
  double wrongPrior() const;
  /// The probability remembered last (0 after reset()).
  double wrongProbability() const { return wrong_probability_; }
  /// Beyond max_mahalanobis of the prediction.
  bool far(const MatchCandidate& candidate) const {
    return candidate.mahalanobis_sq > options_.max_mahalanobis * options_.max_mahalanobis;
  }
  void reset() {
    wrong_probability_ = 0.0;
    pending_ = false;
  }
  const LeapOptions& options() const { return options_; }

 private:
  /// Whether `verdict`'s far wide match asks for the correction the last scan deferred.
  bool confirms(const LeapVerdict& verdict, const LeapHypotheses& h) const;

  LeapOptions options_;
  double wrong_probability_ = 0.0;
  bool pending_ = false;  // the last scan deferred a leap by pending_correction_
  double faults_ = 0.0;   // far leaps (taken or deferred) of scans that fit as usual, forgotten over time
  double scans_ = 0.0;    // scans that fit as usual, forgotten alike
  Pose2D pending_correction_;
  Eigen::Matrix3d pending_covariance_ = Eigen::Matrix3d::Zero();
};

}  // namespace hglasm
