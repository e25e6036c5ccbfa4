// The time policy of one input stream: older stamps are stale, much older ones a new timeline.
#include "hglasm_odometry/core/stamp_order.h"

#include <gtest/gtest.h>

#include <limits>

namespace {

using hglasm::StampOrder;
using Verdict = hglasm::StampOrder::Verdict;

TEST(StampOrder, ForwardOfAnyLengthAndEqualStampsAreInOrder) {
  StampOrder order(3.0);
  EXPECT_EQ(order.newest(), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(order.take(10.0), Verdict::kInOrder);
  EXPECT_EQ(order.take(10.0), Verdict::kInOrder) << "a duplicate stamp is not older";
  EXPECT_EQ(order.take(1e6), Verdict::kInOrder) << "a gap of any length";
  EXPECT_EQ(order.newest(), 1e6);
  EXPECT_EQ(order.staleCount(), 0u);
}

TEST(StampOrder, SlightlyOlderIsStaleAndKeepsTheNewest) {
  StampOrder order(3.0);
  order.take(10.0);
  EXPECT_EQ(order.take(9.999), Verdict::kStale);
  EXPECT_EQ(order.take(7.0), Verdict::kStale) << "exactly reset_on_jump_back behind: not more";
  EXPECT_EQ(order.newest(), 10.0);
  EXPECT_EQ(order.staleCount(), 2u);
  EXPECT_EQ(order.take(10.001), Verdict::kInOrder);
}

TEST(StampOrder, MoreThanTheJumpBehindStartsANewTimeline) {
  StampOrder order(3.0);
  order.take(100.0);
  EXPECT_FALSE(order.behind(97.0));
  EXPECT_TRUE(order.behind(96.9));
  EXPECT_EQ(order.take(0.5), Verdict::kJumpedBack);
  EXPECT_EQ(order.newest(), 0.5);
  EXPECT_EQ(order.jumpsBack(), 1u);
  EXPECT_EQ(order.take(0.6), Verdict::kInOrder) << "the new timeline goes on";
  EXPECT_EQ(order.staleCount(), 0u);
}

TEST(StampOrder, RestartForgetsTheNewest) {
  StampOrder order(3.0);
  order.take(100.0);
  order.restart();
  EXPECT_EQ(order.take(50.0), Verdict::kInOrder);
  EXPECT_EQ(order.jumpsBack(), 0u);
}

}  // namespace
