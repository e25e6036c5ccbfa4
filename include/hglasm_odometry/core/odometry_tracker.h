// Laser odometry: each scan's pose is the maximum a posteriori estimate of the scan matched against a
// local map of keyframes and the motion predicted by wheel odometry (or a constant velocity).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hglasm_odometry/core/keyframe_policy.h"
#include "hglasm_odometry/core/local_map.h"
#include "hglasm_odometry/core/motion_model.h"
#include "hglasm_odometry/core/noise_learner.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/pose_extrapolator.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/core/time_offset_estimator.h"

namespace hglasm {

struct TrackerOptions {
  MatcherOptions matcher;
  ScanConversionOptions conversion;  ///< applied by callers that convert RangeScans (ROS layer, tools)
  LocalMapOptions local_map;
  MotionNoiseOptions motion;
  /// The wheels' noise and the scan's information are scaled by what the matches show (NoiseLearner).
  NoiseLearnerOptions noise_learning;
  /// The wheels' systematic errors, learned from the matches and removed from their motion.
  WheelCalibrationOptions wheel_calibration;
  KeyframeOptions keyframe;
  double min_fitness = 0.15;                 ///< a match whose pose is below this fitness ratio has failed
  int min_points = 20;                       ///< scans with fewer valid points are not matched
  double fallback_covariance_scale = 100.0;  ///< covariance inflation of a step whose match failed
  double odometry_max_extrapolation = 0.25;  ///< seconds; beyond, wheel odometry counts as stale
  /// The wheels' stamps may run late against the scans': learned from the matches, or fixed.
  TimeOffsetOptions odometry_time_offset;
  /// Seconds: a scan, odometry or IMU stamp this far behind the newest of its stream is a clock that jumped
  /// back (a looped bag, a restarted clock): the odometry restarts from the origin (OdometryPipeline). A
  /// stamp less far behind is dropped.
  double reset_on_jump_back = 3.0;
  bool use_odometry = true;
  /// Take the rotation between scans from an IMU (addImu) whenever its samples cover the interval, with
  /// imu's noise model; the wheels (or the velocity) predict the translation, and the rotation while the
  /// IMU is stale or missing.
  bool use_imu = false;
  GyroOptions imu;
  /// Motion-compensate each scan with the current velocity estimate when its beams' times are known
  /// (Scan::time_increment): a sweep taken while moving is sheared, which a match reads as a small turn.
  bool deskew = true;
  /// Wheel odometry implying faster motion than this between two scans is implausible (a jump): the
  /// constant-velocity prediction is used instead. A margin of 0.2 m / 0.2 rad is added for jitter.
  double max_odometry_speed = 5.0;      ///< m/s
  double max_odometry_turn_rate = 6.0;  ///< rad/s
  /// Fuse the scan with the predicted motion (its prior inside the refinement, the search sized by it,
  /// leaps tested). false: the match replaces the prediction, which only centres the preset's box (the
  /// behaviour before fusion; for comparison).
  bool fusion = true;
  /// The GA searches this many standard deviations of the prediction around it on each axis, at least
  /// min_search_xy / min_search_theta and at most the preset's box, and with the GA size of the smallest
  /// of the papers' presets whose box holds that (never more than the configured preset's): the preset is
  /// the robot's worst case, the common case costs less.
  double search_sigmas = 4.0;
  double min_search_xy = 0.10;     ///< metres
  double min_search_theta = 0.05;  ///< radians
  /// The prediction is in doubt when the match (or where the scan alone would put the pose) lies farther
  /// from it than this Mahalanobis distance (3 degrees of freedom), or nothing fits near it. Then a second
  /// hypothesis is searched, "the prediction is wrong" (wheel slip, a glitch, a kidnap): the preset's whole
  /// box with a prior as wide, and the two matches compete by posterior probability: the scan's likelihood
  /// (of its independent points) times each hypothesis' prior. A leap thus needs the evidence to outweigh
  /// the odds against it.
  double max_mahalanobis = 4.0;
  /// Probability that a prediction is wrong beyond its noise model (prior odds of a leap per scan)...
  double leap_probability = 1e-3;
  /// ... and that it stays wrong at the next scan once it was (wheels slip in bursts, a glitch lasts).
  double leap_persistence = 0.5;
  /// Error the models do not explain, added to the published covariance: the standard deviation it
  /// reaches after one second (a random walk in time). Calibrated so that the errors of the Freiburg
  /// relations are covered (README: calibration).
  double unexplained_xy = 0.035;      ///< m per sqrt(s)
  double unexplained_theta = 0.0055;  ///< rad per sqrt(s)
  /// Outlier share of the scan likelihood that weighs leaps: a point far from the map costs log(outlier).
  double likelihood_outlier = 0.1;
};

/// The variance published for what is not known (a covariance must stay finite).
constexpr double kUnknownVariance = 1e4;

/// A pose covariance (x, y, theta) a caller may hand in: finite, symmetric (to 1e-9 relative) and positive
/// semi-definite (to rounding).
bool isValidPoseCovariance(const Eigen::Matrix3d& covariance);

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
  MatchResult match;  ///< raw matcher output (laser frame, local map's frame)
  /// How well the scan fits the local map at the published pose: the cells its points hit on the fine
  /// graded table / (255 * points), 1 = every point on the map; whatever the algorithm, the ratio
  /// min_fitness, keyframe.min_fitness and the doubt about the prediction judge. 0 without a map or a usable
  /// scan.
  double fitness_ratio = 0.0;
  Pose2D guess;  ///< predicted pose of the base (odometry frame) before matching
  PredictionSource prediction = PredictionSource::kNone;
  bool rotation_from_imu =
      false;              ///< the predicted rotation came from the IMU (use_imu and it covered the step)
  double imu_bias = 0.0;  ///< rad/s: the gyro's bias learned so far (subtracted from its rotations)
  SearchEffort search;    ///< box and GA size the scan was searched with
  double prior_mahalanobis = 0.0;   ///< Mahalanobis distance of the match from the prediction
  bool matched = false;             ///< a match was attempted (false for the first scan and after resets)
  bool fallback = false;            ///< match failed: the prediction was integrated instead
  bool prediction_doubted = false;  ///< the match left the prediction: the preset's box was searched too
  bool leap = false;                ///< the estimate leapt from the prediction with the evidence for it
  double leap_probability = 0.0;    ///< posterior probability that the prediction was wrong
  bool jump_rejected = false;  ///< a match far from the prediction lacked the evidence: the prediction held
  bool deskewed = false;       ///< the scan was motion-compensated before matching
  bool new_keyframe = false;
  double table_build_ms = 0.0;  ///< lookup-table build of the new local map (wall ms; 0 if none)
  int keyframe_id = 0;
  int map_keyframes = 0;         ///< keyframes in the local map the scan was matched against
  MotionNoiseScale noise_scale;  ///< the wheel-noise scales learned so far
  ScanNoiseScale scan_noise_scale = ScanNoiseScale::Ones();  ///< the scan's, weakest direction first
  /// The wheels' systematic errors learned so far (WheelCalibration): removed from their motion.
  double wheel_turn_scale = 0.0;
  double wheel_heading_per_metre = 0.0;  ///< rad/m
  double wheel_distance_scale = 0.0;
  /// What the scene constrains: smallest / largest eigenvalue of the scan's information (x, y and theta
  /// weighed as kDirectionLength metres per radian; 0: a direction the scan says nothing about, such as a
  /// featureless corridor's axis) and that weakest direction (x, y, theta; laser in the local map's frame).
  /// 0 and zero without a match.
  double degeneracy = 0.0;
  Eigen::Vector3d weakest_direction = Eigen::Vector3d::Zero();
  /// Seconds the wheels' stamps run late (their pose of the scan's instant was read this much later), and
  /// the best estimate so far (the offset in use until the evidence for it suffices).
  double odometry_time_offset = 0.0;
  double odometry_time_offset_estimate = 0.0;
  bool reset = false;       ///< the tracker restarted (first scan, after reset() or a clock that jumped back)
  bool stale = false;       ///< stamped before the last scan processed: not processed, nothing published
  bool reanchored = false;  ///< the scan did not fit the local map: the map restarted from it
  std::string warning;      ///< non-empty: one line for the log
};

/// Not thread-safe per instance; instances share nothing.
class OdometryTracker {
 public:
  explicit OdometryTracker(const TrackerOptions& options = {});

  /// base -> laser mounting (after mirroring an upside-down laser). Identity by default.
  void setLaserMount(const Pose2D& base_to_laser);
  const Pose2D& laserMount() const { return laser_mount_; }

  /// Wheel odometry: pose of the base in the wheel-odometry frame at `stamp`.
  void addOdometry(double stamp, const Pose2D& odom_pose);

  /// IMU: the base's yaw rate (rad/s) at `stamp`, or its yaw (rad) with options().imu.use_orientation.
  /// Ignored (false) without use_imu or for non-finite values.
  bool addImu(double stamp, double value) { return extrapolator_.addGyro(stamp, value); }

  /// Processes one scan (points in the laser frame) taken at `stamp` (seconds), at or after the last one
  /// processed (an older scan is stale: not processed, update.stale). Forward gaps of any length continue
  /// from the current pose, predicted by the wheels when they cover the gap. If `population_out` is given,
  /// it receives the GA's final population as base poses in the odometry frame (for display).
  TrackerUpdate processScan(double stamp, const Scan& scan, std::vector<Pose2D>* population_out = nullptr);

  /// Forgets the wheel odometry or the IMU samples (they belong to another timeline: a clock went back).
  void clearOdometry() { extrapolator_.clearOdometry(); }
  void clearImu() { extrapolator_.clearGyro(); }
  /// Seconds the wheels' stamps run late against the scans' (in use for the predictions).
  double odometryTimeOffset() const { return time_offset_.offset(); }

  /// Restarts from the identity pose with an empty map (odometry history and learned noise kept).
  void reset();

  /// Restarts like reset(), but from `pose` (the base in the odometry frame at `stamp`, seconds) with
  /// `covariance` (x, y, theta): the next scan becomes the first keyframe, at `pose` composed with the wheel
  /// motion from `stamp` to the scan's stamp (and its noise) when wheel odometry covers both, else at `pose`
  /// as given. Returns false and changes nothing for a non-finite stamp or pose or an invalid covariance
  /// (isValidPoseCovariance).
  bool setPose(double stamp, const Pose2D& pose, const Eigen::Matrix3d& covariance);

  const Pose2D& pose() const { return pose_; }
  const TrackerOptions& options() const { return options_; }
  int keyframeId() const { return keyframe_id_; }
  const LocalMap& localMap() const { return local_map_; }

 private:
  /// The new pose: the laser in the local map's frame, with its covariance there, and the covariance of
  /// the base's increment since the last scan.
  struct Estimate {
    Pose2D laser_in_map;
    Eigen::Matrix3d map_covariance = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d increment_covariance = Eigen::Matrix3d::Zero();
  };
  /// A match and how well it explains the scan.
  struct Candidate {
    MatchResult match;
    double fitness_ratio = 0.0;  ///< of the scan at the match's pose
    bool acceptable = false;
    double mahalanobis_sq = 0.0;
    double log_posterior = 0.0;
  };

  /// The two hypotheses a scan is matched under: the prediction holds (its prior), or it is wrong (a prior
  /// as wide as the preset's box), with the prior probability of the second.
  struct Hypotheses {
    bool informative = false;  ///< fusion on and a motion predicted: the prior holds information
    PosePrior prior;           ///< the laser's predicted pose in the local map's frame
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d motion_covariance = Eigen::Matrix3d::Zero();  ///< the motion's part of it alone
    SearchEffort wide_search;                                     ///< the preset's whole box
    PosePrior wide_prior;
    Eigen::Matrix3d wide_covariance = Eigen::Matrix3d::Zero();
    double wrong_probability = 0.0;
  };

  /// A scan stamped before the last one processed: not processed (the pipeline drops them; a caller of the
  /// tracker alone gets the same).
  bool refuseStale(double stamp, TrackerUpdate* update) const;
  /// Learns the wheels' time offset from where the scan alone put the base.
  void learnTimeOffset(double stamp);
  /// The scan motion-compensated to its stamp (its beams' times known, scan/deskew): the sensor's turn
  /// during the sweep from the IMU when it covers the sweep (a turn rate that changes within it, as when
  /// a spin starts), else from the velocity estimate, which also gives the translation. False: no
  /// compensation (nothing known about the motion yet).
  bool deskew(double stamp, const Scan& sensor_scan, Scan* compensated) const;
  Hypotheses hypothesesFor(const MotionPrediction& prediction) const;
  /// log posterior of a match under each hypothesis (up to a common constant).
  void scoreHypotheses(const Scan& scan, const Hypotheses& h, const MatchResult& match, double* holds,
                       double* wrong) const;
  /// log posterior of "the prediction holds" at the predicted pose itself (when no match near it is
  /// acceptable).
  double predictionScore(const Scan& scan, const Hypotheses& h) const;
  /// If the prediction is in doubt, searches the preset's box too and keeps the more probable match.
  void testLeap(const Scan& scan, const Hypotheses& h, std::vector<Pose2D>* population_out, Candidate* chosen,
                TrackerUpdate* update);
  /// The new pose and its covariances from the chosen match.
  void estimateFrom(const Candidate& chosen, const Hypotheses& h, Estimate* estimate) const;
  void initialise(double stamp, const Scan& scan, bool usable, TrackerUpdate* update);
  /// At the first scan after setPose(): moves the set pose on by the wheel motion since its stamp.
  void advanceSetPose(double stamp, TrackerUpdate* update);
  /// Match against the local map with the prediction as prior; false if the prediction is integrated.
  bool matchScan(const Scan& scan, const MotionPrediction& prediction, std::vector<Pose2D>* population_out,
                 TrackerUpdate* update, Estimate* estimate);
  SearchEffort searchEffort(const Eigen::Matrix3d& prior_covariance, bool have_prior) const;
  Candidate evaluate(const Scan& scan, const MatchResult& match, const PosePrior& prior) const;
  /// Whether a match fits the map as well as matches usually do (within max_mahalanobis of their spread).
  bool fitsAsUsual(double fitness_ratio) const;
  /// Whether the tight match (or the scan alone) disagrees with the prediction beyond its noise.
  bool predictionInDoubt(const Candidate& tight, const PosePrior& prior,
                         const Eigen::Matrix3d& prior_covariance) const;
  /// log p(scan | pose), of the scan's independent points (on the judging table as a likelihood field).
  double scanLogLikelihood(const Scan& scan, const Pose2D& pose) const;
  /// log p(free space | pose): what the likelihood field leaves out, beams that pass through a surface of
  /// the map before their end.
  double freeSpaceLogLikelihood(const Scan& scan, const Pose2D& pose) const;
  /// The fitness ratio of `scan` at `pose` (local map's frame) on the judging table.
  double fitnessRatioAt(const Scan& scan, const Pose2D& pose) const;
  /// The fine graded table of the local map that scans are judged on: the GA's own where it is one (hglasm_g,
  /// glasm_g), else a third table (binary tables; MbICP and PGA alone have only it), so that one yardstick
  /// judges every algorithm (mapTables()).
  const LookupTable& judgingTable() const {
    return local_map_.table(local_map_.tableCount() == 3 ? 2 : kFineTable);
  }
  static constexpr std::size_t kFineTable = 0;  // the local map's tables (mapTables())
  static constexpr std::size_t kCoarseTable = 1;
  /// log of the normal density of `pose` under a prior.
  static double logPrior(const Pose2D& pose, const PosePrior& prior, const Eigen::Matrix3d& covariance);
  /// Learns the wheels' and the scan's noise (if `learn_wheels`: a leap is the wheels' outlier, not their
  /// noise) and the gyro's bias from their increments against the scans' own.
  void learnNoise(const MotionPrediction& prediction, const MatchResult& match, bool learn_wheels);
  /// The learner's sample of this scan: where it alone put the base, the wheels' motion since the last.
  /// Learns the wheels' systematic errors from one step between two matched scans.
  void learnCalibration(const MotionPrediction& prediction, const Pose2D& scan_motion,
                        const Eigen::Matrix3d& scan_covariance);
  NoiseSample noiseSample(const MotionPrediction& prediction, const MatchResult& match,
                          const Pose2D& scan_only) const;
  /// The scan likelihood's weight: its independent points, divided by how far the scan is believed.
  double likelihoodWeight(const Scan& scan) const;
  Estimate integratePrediction(const MotionPrediction& prediction) const;
  void updateVelocity(double stamp, const Pose2D& new_pose, TrackerUpdate* update);
  void updateKeyframe(const Scan& scan, bool usable, TrackerUpdate* update);
  void addKeyframe(const Scan& scan);

  Pose2D toMap(const Pose2D& base_pose) const;
  Pose2D fromMap(const Pose2D& laser_in_map) const;

  TrackerOptions options_;
  ScanMatcher matcher_;
  double table_build_ms_ = 0.0;  // the newest keyframe into the map: its tables and MbICP's reference
  PoseExtrapolator extrapolator_;
  KeyframePolicy keyframes_;
  MotionNoiseModel noise_;
  NoiseLearner noise_learner_;
  WheelCalibration calibration_;
  GyroBiasEstimator gyro_bias_;
  TimeOffsetEstimator time_offset_;
  LocalMap local_map_;
  Pose2D laser_mount_;

  bool initialised_ = false;
  double last_stamp_ = 0.0;
  std::optional<double> set_pose_stamp_;  // setPose()'s stamp until the next scan starts from it
  Pose2D pose_;
  Eigen::Matrix3d pose_covariance_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d map_covariance_ = Eigen::Matrix3d::Zero();  // of the laser pose in the local map's frame
  double prediction_wrong_ = 0.0;  // probability that the last scan's prediction was wrong (a leap)
  /// Mean and variance of recent values, exponentially forgotten.
  struct RunningStats {
    int count = 0;
    double mean = 0.0;
    double variance = 0.0;
    void add(double value);
  };
  RunningStats fitness_;   // of accepted matches: how well scans usually fit the map
  Pose2D scan_only_pose_;  // base pose in the odometry frame where the last scan alone put it
  Eigen::Matrix3d scan_only_covariance_ = Eigen::Matrix3d::Zero();  // ... and its stated covariance
  bool have_scan_rotation_ = false;   // scan_only_pose_ is usable (the gyro's bias learns from it)
  bool have_scan_only_pose_ = false;  // ... and the wheels predicted that scan (their noise learns from it)

  int keyframe_id_ = 0;
  int unexplained_scans_ = 0;  // usable scans in a row the map could not explain
};

}  // namespace hglasm
