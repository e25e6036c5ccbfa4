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

}  // namespace hglasm
