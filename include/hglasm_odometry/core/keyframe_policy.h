// Which scans become keyframes of the local map (as Cartographer's MotionFilter decides which range data
// enter a submap): a scan taken far enough, in distance or heading, from the newest keyframe, or one the map
// no longer explains (its match failed or fit poorly). A scan of another geometry (beam count, first angle,
// increment, range limits) is points like any other: no reason for a keyframe.
#pragma once

#include <cmath>
#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

struct KeyframeOptions {
  double distance = 0.50;    ///< metres moved since the keyframe that make a new keyframe
  double angle = 0.20;       ///< radians turned since the keyframe that make a new keyframe
  double min_fitness = 0.0;  ///< a published pose below this fitness ratio makes the scan a keyframe
  /// Rad/s: a due keyframe waits for a scan taken turning slower than this, while the map still explains
  /// the scans as usual (0: never waits). Keyframes chained through a turn pass each match's heading
  /// error on to the next; with fewer of them the map's heading drifts less, but sparse scans (one per
  /// quarter radian of a turn) can lose the view they need (doc/accuracy.md "Keyframes in turns").
  double max_turn_rate = 0.0;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, KeyframeOptions* options) {
  visitor.positiveNumber("keyframe/distance", &options->distance);
  visitor.number("keyframe/angle", &options->angle, 0.0, M_PI, true);
  visitor.fraction("keyframe/min_fitness", &options->min_fitness);
  visitor.nonNegativeNumber("keyframe/max_turn_rate", &options->max_turn_rate);
}

/// A processed scan as the policy sees it.
struct KeyframeCandidate {
  Pose2D pose;          ///< the base's estimated pose
  bool usable = false;  ///< enough points to be matched (and to be a keyframe)
  bool leapt = false;   ///< the estimate leapt from the prediction
  /// A leap awaits the next scan's confirmation: the scan stays on the prediction...
  bool leap_deferred = false;
  /// ... and the far place fits the map as scans usually do (what wheels that slipped leave).
  bool deferred_leap_fits_as_usual = false;
  bool matched = false;        ///< a match was attempted
  bool match_failed = false;   ///< no match was accepted: the prediction was integrated
  double fitness_ratio = 0.0;  ///< at the estimated pose
  bool fits_as_usual = true;   ///< ... as accepted matches usually fit (FitnessMonitor)
  double turn_rate = 0.0;      ///< rad/s of the base at the scan (its recent poses)
};

/// What becomes of a scan in the local map.
enum class KeyframeAction {
  kNone,        ///< stays out of it
  kAdd,         ///< becomes a keyframe
  kRestartMap,  ///< the map restarts from it (it becomes the only keyframe)
};

/// Not thread-safe per instance.
class KeyframePolicy {
 public:
  explicit KeyframePolicy(const KeyframeOptions& options);

  /// Whether the scan, its base now estimated at `pose`, becomes a keyframe: moved or turned too far since
  /// the keyframe, its match failed (`match_failed`), or, `matched`, its `fitness_ratio` at the estimated
  /// pose is below min_fitness.
  bool wantsKeyframe(const Pose2D& pose, bool matched, bool match_failed, double fitness_ratio) const;

  /// What becomes of `scan` in a local map (empty: `map_empty`). A scan without points to match cannot be a
  /// keyframe, nor one that leapt or whose leap waits (the wheels may be right after all, and a keyframe at
  /// the leap would hold the map to it). A usable scan the map could not explain is an outlier (someone
  /// standing in front of the laser) and stays out; a second one in a row says the map no longer describes
  /// where the robot is (it moved during a pause, the surroundings changed, it turned into a view the map
  /// lacks): the map restarts from it. A scan whose leap waits counts as unexplained when nothing near the
  /// prediction fit and the far place does not fit as usual either: a map that lacks the view offers the
  /// same wrong place to every scan of it, so the next scan would confirm the leap (wheels that slipped
  /// leave the scan a usual fit at the far place; that leap waits as before). After a leap no scan becomes a
  /// keyframe until one fits as usual (`fits_as_usual`) where the leap put the pose: a wrong leap written
  /// into the map is one the next scans fit and keep. Otherwise wantsKeyframe(), unless the base turns
  /// faster than max_turn_rate while the scan fits as usual (the keyframe waits for a slower scan), and
  /// always into an empty map.
  KeyframeAction decide(const KeyframeCandidate& scan, bool map_empty);

  /// A keyframe was added with the base at `pose`.
  void keyframeAdded(const Pose2D& pose) {
    pose_ = pose;
    ++keyframes_;
  }
  /// Keyframes added since construction (the newest keyframe's id).
  int keyframes() const { return keyframes_; }
  /// The odometry restarts with an empty map: no scan before counts as unexplained.
  void restart() {
    unexplained_scans_ = 0;
    unconfirmed_leap_ = false;
  }

 private:
  /// A due keyframe waits: `scan` turns faster than max_turn_rate while the map still explains it.
  bool waitsForSlowerTurn(const KeyframeCandidate& scan) const;

  KeyframeOptions options_;
  Pose2D pose_;  // base pose of the newest keyframe
  int keyframes_ = 0;
  int unexplained_scans_ = 0;      // usable scans in a row the map could not explain
  bool unconfirmed_leap_ = false;  // a leap was taken and no scan has fit as usual since
};

}  // namespace hglasm
