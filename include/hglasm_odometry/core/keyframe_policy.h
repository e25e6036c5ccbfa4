// Which scans become keyframes of the local map (as Cartographer's MotionFilter decides which range data
// enter a submap): a scan taken far enough, in distance or heading, from the newest keyframe, or one the map
// no longer explains (its match failed or fit poorly). A scan of another geometry (beam count, first angle,
// increment, range limits) is points like any other: no reason for a keyframe.
#pragma once

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

/// Not thread-safe per instance.
class KeyframePolicy {
 public:
  /// `distance` (m) and `angle` (rad) moved since the keyframe, a fitness ratio below `min_fitness`.
  KeyframePolicy(double distance, double angle, double min_fitness);

  /// Whether the scan, its base now estimated at `pose`, becomes a keyframe: moved or turned too far since
  /// the keyframe, its match failed (`match_failed`), or, `matched`, its `fitness_ratio` at the estimated
  /// pose is below min_fitness.
  bool wantsKeyframe(const Pose2D& pose, bool matched, bool match_failed, double fitness_ratio) const;

  /// A keyframe was added with the base at `pose`.
  void keyframeAdded(const Pose2D& pose) { pose_ = pose; }

 private:
  double distance_;
  double angle_;
  double min_fitness_;
  Pose2D pose_;  // base pose of the newest keyframe
};

}  // namespace hglasm
