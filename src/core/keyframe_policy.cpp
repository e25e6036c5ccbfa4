#include "hglasm_odometry/core/keyframe_policy.h"

#include <cmath>

namespace hglasm {

KeyframePolicy::KeyframePolicy(const KeyframeOptions& options) : options_(options) {}

bool KeyframePolicy::wantsKeyframe(const Pose2D& pose, bool matched, bool match_failed,
                                   double fitness_ratio) const {
  const Pose2D since_keyframe = relativePose(pose_, pose);
  return match_failed || since_keyframe.translationNorm() > options_.distance ||
         std::abs(since_keyframe.theta) > options_.angle || (matched && fitness_ratio < options_.min_fitness);
}

bool KeyframePolicy::waitsForSlowerTurn(const KeyframeCandidate& scan) const {
  if (!(options_.max_turn_rate > 0.0) || !(std::abs(scan.turn_rate) > options_.max_turn_rate)) return false;
  // Only while the map still explains the scan as usual: once it does not, the view is needed. (decide()
  // asks only after a failed match has been dealt with.)
  return scan.matched && scan.fits_as_usual && scan.fitness_ratio >= options_.min_fitness;
}

KeyframeAction KeyframePolicy::decide(const KeyframeCandidate& scan, bool map_empty) {
  if (scan.leapt) unconfirmed_leap_ = true;
  if (!scan.usable || scan.leapt) return KeyframeAction::kNone;
  if (scan.leap_deferred && scan.deferred_leap_fits_as_usual) return KeyframeAction::kNone;
  const bool unexplained = scan.match_failed && !map_empty;
  const bool restart = unexplained && unexplained_scans_ >= 1;
  unexplained_scans_ = unexplained && !restart ? unexplained_scans_ + 1 : 0;
  if (restart) {
    unconfirmed_leap_ = false;
    return KeyframeAction::kRestartMap;
  }
  if (unexplained || scan.leap_deferred) return KeyframeAction::kNone;
  // A leap is a hypothesis until a scan fits as usual where it put the pose: a keyframe before that would
  // write a wrong leap into the map, where the next scans would fit it and confirm it.
  if (unconfirmed_leap_ && !map_empty) {
    if (!(scan.matched && scan.fits_as_usual)) return KeyframeAction::kNone;
    unconfirmed_leap_ = false;
  }
  const bool wanted = wantsKeyframe(scan.pose, scan.matched, scan.match_failed, scan.fitness_ratio);
  if (map_empty) return KeyframeAction::kAdd;
  return wanted && !waitsForSlowerTurn(scan) ? KeyframeAction::kAdd : KeyframeAction::kNone;
}

}  // namespace hglasm
