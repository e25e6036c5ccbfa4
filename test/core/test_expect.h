// gtest expectations shared by the core tests (test_util.h stays gtest-free: the benchmark uses it too).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "hglasm_odometry/core/pose2d.h"
#include "test_util.h"

namespace hglasm_test {

/// `estimate` within `max_translation` metres and `max_rotation` radians of `truth`; `what` names it.
inline void expectPoseNear(const hglasm::Pose2D& estimate, const hglasm::Pose2D& truth,
                           double max_translation, double max_rotation, const std::string& what) {
  EXPECT_LT(translationError(estimate, truth), max_translation)
      << what << ": " << estimate.x << " " << estimate.y << " " << estimate.theta << " vs " << truth.x << " "
      << truth.y << " " << truth.theta;
  EXPECT_LT(rotationError(estimate, truth), max_rotation)
      << what << ": " << estimate.theta << " vs " << truth.theta;
}

}  // namespace hglasm_test
