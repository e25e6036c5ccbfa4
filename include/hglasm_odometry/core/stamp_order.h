// The time policy of one input stream (scans, wheel odometry, an IMU), as robot_localization's: a message
// stamped before the newest one taken is dropped (a driver's jitter, a reordered bag), unless it is older
// by more than `reset_on_jump_back` seconds: then the clock jumped back (a looped bag, a restarted clock)
// and a new timeline starts. Forward gaps of any length are in order.
#pragma once

#include <cstdint>
#include <limits>

namespace hglasm {

/// Not thread-safe per instance.
class StampOrder {
 public:
  enum class Verdict { kInOrder, kStale, kJumpedBack };

  explicit StampOrder(double reset_on_jump_back) : reset_on_jump_back_(reset_on_jump_back) {}

  /// Judges `stamp` (finite) against the newest stamp taken; kInOrder and kJumpedBack take it.
  Verdict take(double stamp);

  /// The newest stamp taken; -infinity before the first or after restart().
  double newest() const { return newest_; }
  /// Forgets the newest stamp: the next one is in order, whatever it is.
  void restart() { newest_ = -std::numeric_limits<double>::infinity(); }
  /// Whether `stamp` lies on an earlier timeline than this stream's (behind it by more than the jump).
  bool behind(double stamp) const { return stamp < newest_ - reset_on_jump_back_; }

  std::uint64_t staleCount() const { return stale_; }
  std::uint64_t jumpsBack() const { return jumps_back_; }

 private:
  double reset_on_jump_back_;
  double newest_ = -std::numeric_limits<double>::infinity();
  std::uint64_t stale_ = 0;
  std::uint64_t jumps_back_ = 0;
};

const char* toString(StampOrder::Verdict verdict);

}  // namespace hglasm
