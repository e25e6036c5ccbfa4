#include "hglasm_odometry/core/keyframe_policy.h"

#include <cmath>

namespace hglasm {

KeyframePolicy::KeyframePolicy(double distance, double angle, double min_fitness)
    : distance_(distance), angle_(angle), min_fitness_(min_fitness) {}

bool KeyframePolicy::wantsKeyframe(const Pose2D& pose, bool matched, bool match_failed,
                                   double fitness_ratio) const {
  const Pose2D since_keyframe = relativePose(pose_, pose);
  return match_failed || since_keyframe.translationNorm() > distance_ ||
         std::abs(since_keyframe.theta) > angle_ || (matched && fitness_ratio < min_fitness_);
}

}  // namespace hglasm
