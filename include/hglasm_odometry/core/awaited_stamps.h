// What a scan waiting for its inputs waits for: shared by the pipeline, which knows (awaitedFor), and the
// node's input queue, which wakes the waiting worker only when it arrives.
#pragma once

#include <limits>

namespace hglasm {

/// A wheel (IMU) sample stamped at or after `wheels` (`imu`) is awaited; +infinity: none of that input.
struct AwaitedStamps {
  double wheels = std::numeric_limits<double>::infinity();
  double imu = std::numeric_limits<double>::infinity();

  /// Any sample of either input (what a wait without a scan's stamps wakes for).
  static AwaitedStamps anySample() {
    return {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  }
  bool nothing() const {
    return wheels == std::numeric_limits<double>::infinity() &&
           imu == std::numeric_limits<double>::infinity();
  }
};

}  // namespace hglasm
