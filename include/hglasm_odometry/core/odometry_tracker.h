// Laser odometry: keyframes, prediction (wheel odometry or constant velocity), failure policy.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"

namespace hglasm {

struct TrackerOptions {
  MatcherOptions matcher;
  ScanConversionOptions conversion;   ///< applied by callers that convert RangeScans (ROS layer, tools)
  double keyframe_distance = 0.30;    ///< metres moved since the keyframe that make a new keyframe
  double keyframe_angle = 0.20;       ///< radians turned since the keyframe that make a new keyframe
  double keyframe_min_fitness = 0.0;  ///< a match below this fitness ratio makes the scan a keyframe
  double min_fitness = 0.15;          ///< a match below this fitness ratio counts as failed
  int min_points = 20;                ///< scans with fewer valid points are not matched
  double fallback_covariance_scale = 100.0;  ///< covariance inflation of a fallback step
  double odometry_max_extrapolation = 0.25;  ///< seconds; beyond, wheel odometry counts as stale
  double max_time_jump = 60.0;        ///< seconds forward between scans that triggers a reset
  bool use_odometry = true;
  /// Motion-compensate each scan with the current velocity estimate when its beams' times are known
  /// (Scan::time_increment): a sweep taken while moving is sheared, which a match reads as a small turn.
  bool deskew = true;
  /// Wheel odometry implying faster motion than this between two scans is implausible (a jump): the
  /// constant-velocity prediction is used instead. A margin of 0.2 m / 0.2 rad is added for jitter.
  double max_odometry_speed = 5.0;       ///< m/s
  double max_odometry_turn_rate = 6.0;   ///< rad/s
  /// A match farther than jump_distance + jump_fraction * |predicted motion| (or jump_angle +
  /// jump_fraction * |predicted turn|) from an odometry or constant-velocity prediction is checked: MbICP
  /// alone refines the prediction too, and the pre-aligned result is kept only if it fits the reference
  /// better by jump_margin (fitness ratio). Stops the GA from leaping to a look-alike place (a corridor).
  double jump_distance = 0.20;      ///< metres
  double jump_angle = 0.15;         ///< radians
  double jump_fraction = 0.25;
  double jump_margin = 0.02;
  /// A far match is kept only if its fitness ratio also reaches this fraction of the recent matches'
  /// (a running mean): a leap needs strong evidence. If MbICP from the prediction strays as far, the
  /// scene is not trustworthy (a crowd, a door swinging) and the prediction is integrated instead.
  double jump_min_relative_fitness = 0.0;
  /// Odometry translation noise per metre and rotation noise per radian (for the guess covariance).
  double odometry_noise_xy = 0.05;
  double odometry_noise_theta = 0.05;
};

enum class PredictionSource { kOdometry, kConstantVelocity, kNone };
const char* toString(PredictionSource source);

/// What happened to one scan.
struct TrackerUpdate {
  double stamp = 0.0;
  bool published = false;     ///< false only for scans that carry no pose (first scan is published)
  Pose2D pose;                ///< base frame in the odometry frame
  Eigen::Matrix3d pose_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< vx, vy, wz in the base frame
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Identity();
  MatchResult match;          ///< raw matcher output (laser frame, keyframe reference)
  Pose2D guess;               ///< predicted pose of the base (odometry frame) before matching
  PredictionSource prediction = PredictionSource::kNone;
  bool matched = false;       ///< a match was attempted (false for the first scan and after resets)
  bool fallback = false;      ///< match failed: the prediction was integrated instead
  bool jump_rejected = false; ///< the pre-aligned match strayed from the prediction and lost to it
  bool deskewed = false;      ///< the scan was motion-compensated before matching
  bool new_keyframe = false;
  double table_build_ms = 0.0;  ///< lookup-table build of the new keyframe (wall ms; 0 if none)
  int keyframe_id = 0;
  bool reset = false;         ///< the tracker restarted (time jump, first scan after reset())
  std::string warning;        ///< non-empty: one line for the log
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

  /// Processes one scan (points in the laser frame) taken at `stamp` (seconds). If `population_out` is
  /// given, it receives the GA's final population as base poses in the odometry frame (for display).
  TrackerUpdate processScan(double stamp, const Scan& scan,
                            std::vector<Pose2D>* population_out = nullptr);

  /// Makes the next processed scan a keyframe (e.g. the scanner's geometry changed).
  void requestKeyframe() { keyframe_requested_ = true; }

  /// Restarts from the identity pose with no keyframe (odometry history kept).
  void reset();

  const Pose2D& pose() const { return pose_; }
  const TrackerOptions& options() const { return options_; }
  int keyframeId() const { return keyframe_id_; }

 private:
  PredictionSource predict(double stamp, Pose2D* predicted, std::string* warning) const;
  void guardAgainstJump(const Scan& scan, const Pose2D& laser_guess, PredictionSource prediction,
                        TrackerUpdate* update);
  void setKeyframe(const Scan& scan, const Pose2D& pose,
                   const Eigen::Matrix3d& covariance);

  TrackerOptions options_;
  ScanMatcher matcher_;
  OdometryBuffer odometry_;
  Pose2D laser_mount_;

  bool initialised_ = false;
  double last_stamp_ = 0.0;
  Pose2D pose_;
  Eigen::Matrix3d pose_covariance_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();
  double recent_fitness_ = 0.0;  // running mean of accepted matches' fitness ratios (0: none yet)
  bool velocity_valid_ = false;

  std::deque<StampedPose> history_;  // recent poses, for the velocity
  bool has_keyframe_ = false;
  bool keyframe_requested_ = false;
  int keyframe_id_ = 0;
  int keyframe_beam_count_ = 0;
  Pose2D keyframe_pose_;
  Eigen::Matrix3d keyframe_covariance_ = Eigen::Matrix3d::Zero();
};

}  // namespace hglasm
