// Which scans become keyframes of the local map (as Cartographer's MotionFilter decides which range data
// enter a submap): a scan taken far enough, in distance or heading, from the newest keyframe, or one the map
// no longer explains (its match failed or fit poorly). A scan of another geometry (beam count, first angle,
// increment, range limits) is points like any other: no reason for a keyframe.
#pragma once

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

struct KeyframeOptions {
  double distance = 0.30;    ///< metres moved since the keyframe that make a new keyframe
  double angle = 0.20;       ///< radians turned since the keyframe that make a new keyframe
  double min_fitness = 0.0;  ///< a published pose below this fitness ratio makes the scan a keyframe
};

/// Not thread-safe per instance.
class KeyframePolicy {
 public:
  explicit KeyframePolicy(const KeyframeOptions& options);

  /// Whether the scan, its base now estimated at `pose`, becomes a keyframe: moved or turned too far since
  /// the keyframe, its match failed (`match_failed`), or, `matched`, its `fitness_ratio` at the estimated
  /// pose is below min_fitness.
  bool wantsKeyframe(const Pose2D& pose, bool matched, bool match_failed, double fitness_ratio) const;

  /// A keyframe was added with the base at `pose`.
  void keyframeAdded(const Pose2D& pose) { pose_ = pose; }

 private:
  KeyframeOptions options_;
  Pose2D pose_;  // base pose of the newest keyframe
};

}  // namespace hglasm
