#include "hglasm_odometry/core/stamp_order.h"

namespace hglasm {

StampOrder::Verdict StampOrder::take(double stamp) {
  if (!(stamp < newest_)) {
    newest_ = stamp;
    return Verdict::kInOrder;
  }
  if (behind(stamp)) {
    newest_ = stamp;
    ++jumps_back_;
    return Verdict::kJumpedBack;
  }
  ++stale_;
  return Verdict::kStale;
}

const char* toString(StampOrder::Verdict verdict) {
  switch (verdict) {
    case StampOrder::Verdict::kInOrder:
      return "in_order";
    case StampOrder::Verdict::kStale:
      return "stale";
    case StampOrder::Verdict::kJumpedBack:
      return "jumped_back";
  }
  return "unknown";
}

}  // namespace hglasm
