// RingBuffer: first in first out across the wrap, the limit drops the oldest, push_front refuses when
// full, the storage grows to the most held and is then reused, swapElements keeps each side's limit.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "hglasm_odometry/ros/ring_buffer.h"

namespace hglasm_odometry {
namespace {

std::vector<int> contents(const RingBuffer<int>& ring) {
  std::vector<int> values;
  for (std::size_t i = 0; i < ring.size(); ++i) values.push_back(ring[i]);
  return values;
}

TEST(RingBuffer, FirstInFirstOutAcrossTheWrapAndGrowth) {
  RingBuffer<int> ring;
  int next_in = 0, next_out = 0;
  // Interleave so the head moves around the storage while it grows.
  for (int round = 0; round < 50; ++round) {
    for (int i = 0; i < 3; ++i) ring.push_back(next_in++);
    ASSERT_EQ(ring.front(), next_out);
    ring.pop_front();
    ++next_out;
  }
  ASSERT_EQ(ring.size(), static_cast<std::size_t>(next_in - next_out));
  for (std::size_t i = 0; i < ring.size(); ++i) EXPECT_EQ(ring[i], next_out + static_cast<int>(i));
  EXPECT_EQ(ring.back(), next_in - 1);
}

TEST(RingBuffer, TheLimitDropsTheOldest) {
  RingBuffer<int> ring(3);
  EXPECT_FALSE(ring.push_back(1));
  EXPECT_FALSE(ring.push_back(2));
  EXPECT_FALSE(ring.push_back(3));
  EXPECT_TRUE(ring.full());
  EXPECT_TRUE(ring.push_back(4));
  EXPECT_EQ(contents(ring), (std::vector<int>{2, 3, 4}));
  EXPECT_EQ(ring.capacity(), 3u);  // never more than the limit
}

TEST(RingBuffer, PushFrontPutsBeforeTheOldestUnlessFull) {
  RingBuffer<int> ring(3);
  ring.push_back(2);
  EXPECT_TRUE(ring.push_front(1));
  ring.push_back(3);
  EXPECT_FALSE(ring.push_front(0));
  EXPECT_EQ(contents(ring), (std::vector<int>{1, 2, 3}));
}

TEST(RingBuffer, StorageIsReusedOnceGrown) {
  RingBuffer<int> ring(1000);
  for (int i = 0; i < 100; ++i) ring.push_back(i);
  const std::size_t grown = ring.capacity();
  ring.clear();
  EXPECT_TRUE(ring.empty());
  for (int cycle = 0; cycle < 20; ++cycle) {
    for (int i = 0; i < 100; ++i) ring.push_back(i);
    for (int i = 0; i < 100; ++i) ring.pop_front();
  }
  EXPECT_EQ(ring.capacity(), grown);
}

TEST(RingBuffer, PopReleasesTheElementAtOnce) {
  RingBuffer<std::shared_ptr<int>> ring;
  auto value = std::make_shared<int>(7);
  ring.push_back(value);
  EXPECT_EQ(value.use_count(), 2);
  ring.pop_front();
  EXPECT_EQ(value.use_count(), 1);
}

TEST(RingBuffer, SwapElementsKeepsEachLimit) {
  RingBuffer<int> bounded(2), taker;
  bounded.push_back(1);
  bounded.push_back(2);
  taker.swapElements(bounded);
  EXPECT_TRUE(bounded.empty());
  EXPECT_EQ(contents(taker), (std::vector<int>{1, 2}));
  EXPECT_EQ(bounded.limit(), 2u);
  bounded.push_back(3);
  bounded.push_back(4);
  EXPECT_TRUE(bounded.push_back(5));  // still bounded after the swap
  EXPECT_EQ(contents(bounded), (std::vector<int>{4, 5}));
}

}  // namespace
}  // namespace hglasm_odometry
