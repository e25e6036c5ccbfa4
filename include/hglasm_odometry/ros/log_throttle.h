// Per-instance log throttling: rosconsole's THROTTLE macros keep one timer per call site, shared by every
// instance in the process (two odometries in one manager would silence each other). ROS-free; not
// thread-safe (the worker is the only thread that warns repeatedly).
#pragma once

#include <map>
#include <string>

namespace hglasm_odometry {

class LogThrottle {
 public:
  /// True (and the time noted) unless `key` was let through less than `period` seconds before `now`.
  bool allow(const std::string& key, double now, double period) {
    const auto last = last_.find(key);
    if (last != last_.end() && now - last->second < period) return false;
    last_[key] = now;
    return true;
  }

 private:
  std::map<std::string, double> last_;  // key -> when it was last let through
};

}  // namespace hglasm_odometry
