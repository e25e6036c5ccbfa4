// Laser odometry: each scan's pose is the maximum a posteriori estimate of the scan matched against a
// local map of keyframes and the motion predicted by wheel odometry (or a constant velocity). The tracker
// orchestrates classes that each own one piece of state: the prediction (PoseExtrapolator), what the
// matches teach about the sensors (SensorLearner), leaps from the prediction (LeapDetector), how well scans
// usually fit (FitnessMonitor), which scans become keyframes (KeyframePolicy) and the map (LocalMap).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "hglasm_odometry/core/covariance.h"
#include "hglasm_odometry/core/fitness_monitor.h"
#include "hglasm_odometry/core/keyframe_policy.h"
#include "hglasm_odometry/core/leap_detector.h"
#include "hglasm_odometry/core/local_map.h"
#include "hglasm_odometry/core/motion_model.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/pose_extrapolator.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/core/search_sizing.h"
#include "hglasm_odometry/core/sensor_learner.h"

namespace hglasm {

/// What the published covariance holds beyond the models'.
struct UncertaintyOptions {
  double fallback_scale = 100.0;  ///< covariance inflation of a step whose match failed
  /// Error the models do not explain (timing, the scans' distortion, the surfaces' own errors): the
  /// standard deviation it reaches after one second, a random walk in time. Calibrated so that the errors
  /// of the Freiburg relations are covered (doc/accuracy.md).
  double unexplained_xy = 0.035;      ///< m per sqrt(s)
  double unexplained_theta = 0.0055;  ///< rad per sqrt(s)
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, UncertaintyOptions* options) {
  visitor.number("fallback_covariance_scale", &options->fallback_scale, 1.0, 1e12);
  visitor.nonNegativeNumber("covariance/unexplained_xy", &options->unexplained_xy);
  visitor.nonNegativeNumber("covariance/unexplained_theta", &options->unexplained_theta);
}

struct TrackerOptions {
  MatcherOptions matcher;
  ScanConversionOptions conversion;  ///< applied by callers that convert RangeScans (ROS layer, tools)
  LocalMapOptions local_map;
  KeyframeOptions keyframe;
  PoseExtrapolatorOptions prediction;  ///< the wheels, the IMU, the velocity
  MotionNoiseOptions motion;           ///< the wheels' (and the constant velocity's) noise model
  SensorLearningOptions learning;      ///< what is learned from the matches
  SearchOptions search;                ///< the GA's box around the prediction
  LeapOptions leap;
  UncertaintyOptions uncertainty;
  double min_fitness = 0.15;  ///< a match whose pose is below this fitness ratio has failed
  int min_points = 20;        ///< scans with fewer valid points are not matched
  /// Fuse the scan with the predicted motion (its prior inside the refinement, the search sized by it,
  /// leaps tested). false: the match replaces the prediction, which only centres the preset's box (for
  /// comparison).
  bool fusion = true;
  /// Motion-compensate each scan with the current motion estimate when its beams' times are known
  /// (Scan::time_increment; deskew.h).
  bool deskew = true;
  /// Seconds: a scan, odometry or IMU stamp this far behind the newest of its stream is a clock that jumped
  /// back (a looped bag, a restarted clock): the odometry restarts from the origin (OdometryPipeline). A
  /// stamp less far behind is dropped.
  double reset_on_jump_back = 3.0;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, TrackerOptions* options) {
  visitOptions(visitor, &options->keyframe);
  visitor.fraction("min_fitness", &options->min_fitness);
  visitor.positiveInteger("min_points", &options->min_points);
  visitor.positiveNumber("time/reset_on_jump_back", &options->reset_on_jump_back);
  visitor.boolean("fusion", &options->fusion);
  visitOptions(visitor, &options->uncertainty);
  visitOptions(visitor, &options->search);
  visitOptions(visitor, &options->leap);
  visitOptions(visitor, &options->local_map);
  visitOptions(visitor, &options->prediction);
  visitOptions(visitor, &options->learning);
  visitOptions(visitor, &options->motion);
  visitOptions(visitor, &options->conversion);
  visitor.boolean("scan/deskew", &options->deskew);
  visitOptions(visitor, &options->matcher);
}

/// Constraints between its parameters, checked once every layer is applied: "" if met, else one line
/// naming the parameter after `prefix` ("~").
std::string inconsistency(const TrackerOptions& options, const std::string& prefix);

/// How one scan was predicted, searched, matched and judged, and what is learned so far: for the node's
/// Match message and diagnostics and for `evaluate --trace`.
struct TrackerDiagnostics {
  Pose2D guess;  ///< predicted pose of the base (odometry frame) before matching
  PredictionSource prediction = PredictionSource::kNone;
  bool rotation_from_imu = false;  ///< the predicted rotation came from the IMU
  bool deskewed = false;           ///< the scan was motion-compensated before matching
  SearchEffort search;             ///< box and GA size the scan was searched with
  MatchResult match;               ///< raw matcher output (laser frame, local map's frame)
  int map_keyframes = 0;           ///< keyframes in the local map the scan was matched against
  /// How well the scan fits the local map at the published pose (ScanJudge::fitnessRatio); 0 without a
  /// map or a usable scan.
  double fitness_ratio = 0.0;
  double prior_mahalanobis = 0.0;  ///< Mahalanobis distance of the match from the prediction
  /// The scale the wheels' prior information was refined under after the slip test (1: as predicted;
  /// LeapOptions::slip_variance_scale).
  double prior_weight = 1.0;
  /// What the scene constrains (InformationDirections of the match): 0 for a direction the scan says
  /// nothing about (a featureless corridor's axis), and that weakest direction (x, y, theta). 0 and zero
  /// without a match.
  double degeneracy = 0.0;
  Eigen::Vector3d weakest_direction = Eigen::Vector3d::Zero();
  bool prediction_doubted = false;  ///< the match left the prediction: the preset's box was searched too
  bool jump_rejected = false;  ///< a match far from the prediction lacked the evidence: the prediction held
  /// A far match won but waits for the next scan to ask for the same correction (LeapOptions::confirm):
  /// the prediction held this time, and the scan is no keyframe.
  bool leap_deferred = false;
  /// ... and that far match fits the map as scans usually do (the signature of wheels that slipped, where
  /// a map that lacks the view fits nowhere as usual).
  bool deferred_leap_fits_as_usual = false;
  /// The published pose fits the map as accepted matches usually do (FitnessMonitor, judged before this
  /// scan's own fit joins it); true when no match was made.
  bool fits_as_usual = true;
  double leap_probability = 0.0;  ///< posterior probability that the prediction was wrong
  bool reanchored = false;        ///< the scan did not fit the local map: the map restarted from it
  double table_build_ms = 0.0;    ///< lookup-table build of the new local map (wall ms; 0 if none)
  /// Seconds the wheels' stamps run late, as this scan's prediction read them, and the best estimate so
  /// far (the offset in use until the evidence for it suffices).
  double odometry_time_offset = 0.0;
  double odometry_time_offset_estimate = 0.0;
  LearnedModels learned;  ///< after this scan (a restart reports the wheels' noise scales only)
};

/// What happened to one scan.
struct TrackerUpdate {
  double stamp = 0.0;
  bool published = false;  ///< false only for scans that carry no pose (first scan is published)
  Pose2D pose;             ///< base frame in the odometry frame
  Eigen::Matrix3d pose_covariance = Eigen::Matrix3d::Zero();
  /// Covariance of the motion since the previous published pose, in that pose's frame (x, y, theta): the
  /// uncertainty this scan adds; pose_covariance is these composed.
  Eigen::Matrix3d increment_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< vx, vy, wz in the base frame
  /// Unknown (kUnknownVariance on the diagonal) until the velocity has a baseline: the first scans, after
  /// a reset.
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Identity() * kUnknownVariance;
  bool reset = false;     ///< the tracker restarted (first scan, after reset() or a clock that jumped back)
  bool stale = false;     ///< stamped before the last scan processed: not processed, nothing published
  bool matched = false;   ///< a match was attempted (false for the first scan and after resets)
  bool fallback = false;  ///< no match was accepted: the prediction was integrated instead
  bool leap = false;      ///< the estimate leapt from the prediction with the evidence for it
  bool new_keyframe = false;
  int keyframe_id = 0;  ///< keyframes so far
  std::string warning;  ///< non-empty: one line for the log
  TrackerDiagnostics diagnostics;
};

/// Not thread-safe per instance; instances share nothing.
class OdometryTracker {
 public:
  explicit OdometryTracker(const TrackerOptions& options = {});

  /// base -> laser mounting (after mirroring an upside-down laser). Identity by default.
  void setLaserMount(const Pose2D& base_to_laser);
  const Pose2D& laserMount() const { return laser_mount_; }
  /// The mount in use: the stated one moved towards the lever arm learned so far (WheelCalibration, with
  /// odometry/calibration/laser_offset), at most kMaxMountChange per matched scan so that the base's pose
  /// stays continuous.
  Pose2D mountInUse() const;
  static constexpr double kMaxMountChange = 0.001;  // m

  /// Wheel odometry: pose of the base in the wheel-odometry frame at `stamp`.
  void addOdometry(double stamp, const Pose2D& odom_pose) { extrapolator_.addOdometry(stamp, odom_pose); }

  /// IMU: the base's yaw rate (rad/s) at `stamp`, or its yaw (rad) with options().prediction.imu's
  /// use_orientation. Ignored (false) without use_imu or for non-finite values.
  bool addImu(double stamp, double value) { return extrapolator_.addImu(stamp, value); }

  /// Processes one scan (points in the laser frame) taken at `stamp` (seconds), at or after the last one
  /// processed (an older scan is stale: not processed, update.stale). Forward gaps of any length continue
  /// from the current pose, predicted by the wheels when they cover the gap. If `population_out` is given,
  /// it receives the GA's final population as base poses in the odometry frame (for display).
  TrackerUpdate processScan(double stamp, const Scan& scan, std::vector<Pose2D>* population_out = nullptr);

  /// Forgets the wheel odometry or the IMU samples (they belong to another timeline: a clock went back).
  void clearOdometry() { extrapolator_.clearOdometry(); }
  void clearImu() { extrapolator_.clearImu(); }
  /// Seconds the wheels' stamps run late against the scans' (in use for the predictions).
  double odometryTimeOffset() const { return learner_.odometryTimeOffset().offset(); }

  /// Restarts from the identity pose with an empty map (odometry history and learned noise kept).
  void reset();

  /// Restarts like reset(), but from `pose` (the base in the odometry frame at `stamp`, seconds) with
  /// `covariance` (x, y, theta): the next scan becomes the first keyframe, at `pose` composed with the wheel
  /// motion from `stamp` to the scan's stamp (and its noise) when wheel odometry covers both, else at `pose`
  /// as given. Returns false and changes nothing for a non-finite stamp or pose or an invalid covariance
  /// (isValidPoseCovariance).
  bool setPose(double stamp, const Pose2D& pose, const Eigen::Matrix3d& covariance);

  /// The base in the odometry frame, as published (the frame tf's stated mount defines).
  Pose2D pose() const;
  const TrackerOptions& options() const { return options_; }
  int keyframeId() const { return keyframes_.keyframes(); }
  const LocalMap& localMap() const { return local_map_; }

 private:
  /// The new pose: the laser in the local map's frame, with its covariance there, and the covariance of
  /// the base's increment since the last scan.
  struct Estimate {
    Pose2D laser_in_map;
    Eigen::Matrix3d map_covariance = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d increment_covariance = Eigen::Matrix3d::Zero();
  };
  /// The laser's predicted pose in the local map's frame: the previous estimate's uncertainty there plus
  /// the motion's noise.
  struct Prior {
    bool informative = false;  ///< fusion on and a motion predicted: the prior holds information
    Pose2D mean;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d motion_covariance = Eigen::Matrix3d::Zero();  ///< the motion's part of it alone
  };

  /// A non-finite or stale stamp (before the last scan processed): not processed (the pipeline drops stale
  /// scans; a caller of the tracker alone gets the same).
  bool refuse(double stamp, TrackerUpdate* update) const;
  /// The scan motion-compensated to its stamp (deskewSweep) with the IMU's turn and the velocity estimate;
  /// false: no compensation.
  bool deskew(double stamp, const Scan& sensor_scan, Scan* compensated) const;
  void initialise(double stamp, const Scan& scan, bool usable, TrackerUpdate* update);
  /// At the first scan after setPose(): moves the set pose on by the wheel motion since its stamp.
  void advanceSetPose(double stamp, TrackerUpdate* update);
  MotionPrediction predict(double stamp, TrackerUpdate* update) const;
  /// Replaces the prediction's motion and covariances by the wheels' motion from unconfirmed_since_ to
  /// `stamp`, expressed from pose_; unchanged where the wheels do not cover that span.
  void predictFromAnchor(double stamp, MotionPrediction* prediction) const;
  /// Where the match's innovation says the wheels more likely slipped than not, MbICP refines again under
  /// their prior softened by LeapDetector::priorWeight(); kept where the scan fits the map better there.
  void refineIfSlipped(const Scan& scan, const ScanJudge& scan_judge, const MotionPrediction& prediction,
                       const LeapHypotheses& h, MatchCandidate* tight, TrackerDiagnostics* diagnostics);
  Prior priorFor(const MotionPrediction& prediction) const;
  /// Matches against the local map with the prediction as prior, tests for a leap, learns from the match;
  /// false if no match is acceptable (the prediction is integrated).
  bool matchScan(const Scan& scan, const MotionPrediction& prediction, std::vector<Pose2D>* population_out,
                 TrackerUpdate* update, Estimate* estimate);
  /// The leap test's verdict and the chosen match, into the update.
  void record(const LeapVerdict& verdict, TrackerUpdate* update) const;
  /// The scan against the local map's fine table, in one judge rebound at every call (its memory reused):
  /// the reference is valid until the next call, and while the scan and the map stay unchanged.
  const ScanJudge& judge(const Scan& scan);
  MatchCandidate candidate(const ScanJudge& judge, const MatchResult& match, const PosePrior& prior) const;
  /// The new pose and its covariances from the chosen match.
  Estimate estimateFrom(const MatchCandidate& chosen, const Prior& prior) const;
  Estimate integratePrediction(const MotionPrediction& prediction) const;
  /// Where the match's scan alone put the base, for the learner.
  ScanOnlyPose scanOnlyPose(const MatchResult& match) const;
  /// The wheels' time offset from where the scan alone put the base.
  void learnTimeOffset(double stamp);
  /// Hands what the learner knows to the extrapolator and the matcher.
  void applyLearnedModels();
  /// Moves the mount in use towards the learned lever arm (once per matched scan, kMaxMountChange at most).
  void moveMountTowardsLearned();
  /// Moves the estimate on to `estimate` at `stamp`: pose, covariances, velocity.
  void advance(double stamp, Estimate estimate, TrackerUpdate* update);
  void updateVelocity(double stamp, const Pose2D& new_pose, TrackerUpdate* update);
  void updateMap(const Scan& scan, bool usable, TrackerUpdate* update);
  void addKeyframe(const Scan& scan, TrackerUpdate* update);
  void publish(TrackerUpdate* update) const;
  /// update->pose and pose_covariance: pose_ in the frame tf's stated mount defines.
  void publishPose(TrackerUpdate* update) const;
  /// The tracker's pose (the frame the wheels move) of a pose in the published frame.
  Pose2D publishedToInternal(const Pose2D& published) const;
  /// The published frame in the tracker's: moved by the lever arm applied so far.
  Pose2D leverArm() const;

  /// The predicted base motion as the laser makes it (the mount's lever arm), and its covariance.
  Pose2D laserMotion(const Pose2D& base_motion) const;
  Eigen::Matrix3d laserMotionCovariance(const MotionPrediction& prediction) const;
  Pose2D laserInMap(const Pose2D& base_pose) const;
  Pose2D baseInOdometry(const Pose2D& laser_in_map) const;

  TrackerOptions options_;
  ScanMatcher matcher_;
  LocalMap local_map_;
  PoseExtrapolator extrapolator_;
  SensorLearner learner_;
  LeapDetector leap_detector_;
  FitnessMonitor fitness_;
  ScanJudge scan_judge_;  // judge()'s, rebound at every call
  KeyframePolicy keyframes_;
  Pose2D laser_mount_;
  Eigen::Vector2d applied_laser_offset_ = Eigen::Vector2d::Zero();  // m, base frame

  bool initialised_ = false;
  double last_stamp_ = 0.0;
  std::optional<double> set_pose_stamp_;  // setPose()'s stamp until the next scan starts from it
  /// The last pose a scan or the wheels stand behind, while pose_ is a guess no scan confirmed (a
  /// constant-velocity prediction integrated): the wheels' next prediction starts from there instead.
  struct Anchor {
    double stamp;
    Pose2D pose;
  };
  std::optional<Anchor> unconfirmed_since_;
  Pose2D pose_;
  Eigen::Matrix3d pose_covariance_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d map_covariance_ = Eigen::Matrix3d::Zero();  // of the laser pose in the local map's frame
};

}  // namespace hglasm
