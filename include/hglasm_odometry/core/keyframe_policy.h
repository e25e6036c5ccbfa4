// Which scans become keyframes of the local map (as Cartographer's MotionFilter decides which range data
// enter a submap): a scan taken far enough, in distance or heading, from the newest keyframe; one the map
// no longer explains (its match failed or fit poorly); the first with another scanner geometry; or any scan
// on request.
#pragma once

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

/// Not thread-safe per instance.
class KeyframePolicy {
 public:
  /// `distance` (m) and `angle` (rad) moved since the keyframe, a fitness ratio below `min_fitness`.
  KeyframePolicy(double distance, double angle, double min_fitness);

  /// Makes the next scan that can be one a keyframe (e.g. the scanner's geometry changed).
  void request() { requested_ = true; }

  /// The scan's beam count differs from the newest keyframe's: another scanner geometry.
  bool scannerChanged(int beam_count) const { return beam_count != beam_count_; }
  int keyframeBeamCount() const { return beam_count_; }

  /// Whether the scan, its base now estimated at `pose`, becomes a keyframe: requested, moved or turned too
  /// far since the keyframe, its match failed (`match_failed`), or, `matched`, its `fitness_ratio` at the
  /// estimated pose is below min_fitness.
  bool wantsKeyframe(const Pose2D& pose, bool matched, bool match_failed, double fitness_ratio) const;

  /// A keyframe was added with the base at `pose` from a scan of `beam_count` beams.
  void keyframeAdded(const Pose2D& pose, int beam_count);

  /// Forgets a pending request (the tracker restarts: its first usable scan is a keyframe anyway).
  void cancelRequest() { requested_ = false; }

 private:
  double distance_;
  double angle_;
  double min_fitness_;
  bool requested_ = false;
  Pose2D pose_;  // base pose of the newest keyframe
  int beam_count_ = 0;
};

}  // namespace hglasm
