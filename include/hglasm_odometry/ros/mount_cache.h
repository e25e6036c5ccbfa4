// Where a sensor sits on the robot (base_frame -> the frame its messages carry), found on tf once per frame:
// mounts are static, and a tf lookup per message would cost more than the message. While tf lacks a frame,
// it is asked again at most every `retry_seconds`. ROS-free (the lookup is the caller's); not thread-safe.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hglasm_odometry {

template <typename Mount>
class MountCache {
 public:
  enum class Result {
    kCached,  ///< known already
    kFound,   ///< looked up now (and remembered)
    kMissing  ///< the lookup failed, now or less than retry_seconds ago
  };

  /// `capacity`: frames remembered; a new frame beyond it replaces the oldest (1: only the frame of the
  /// latest message counts, and a change of frame is looked up again).
  explicit MountCache(double retry_seconds = 0.0,
                      std::size_t capacity = std::numeric_limits<std::size_t>::max())
      : retry_seconds_(retry_seconds), capacity_(capacity) {}

  /// The mount of `frame` into *mount. Asks `lookup(frame, &mount)` (false while tf lacks it) unless the
  /// frame is known or a lookup failed less than retry_seconds before `now` (seconds, the caller's clock).
  template <typename Lookup>
  Result find(std::string_view frame, double now, Lookup&& lookup, Mount* mount) {
    for (const auto& known : mounts_) {
      if (known.first == frame) {
        *mount = known.second;
        return Result::kCached;
      }
    }
    if (now < retry_at_) return Result::kMissing;
    if (!lookup(frame, mount)) {
      retry_at_ = now + retry_seconds_;
      return Result::kMissing;
    }
    if (mounts_.size() >= capacity_ && !mounts_.empty()) mounts_.erase(mounts_.begin());
    mounts_.emplace_back(std::string(frame), *mount);
    return Result::kFound;
  }

 private:
  double retry_seconds_;
  std::size_t capacity_;
  double retry_at_ = -std::numeric_limits<double>::infinity();
  std::vector<std::pair<std::string, Mount>> mounts_;  // oldest first; a robot has a few sensor frames
};

}  // namespace hglasm_odometry
