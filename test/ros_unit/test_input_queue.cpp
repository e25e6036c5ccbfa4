// InputQueue: the bounded scan queue (oldest dropped and counted, a held scan back at the front), samples
// and requests taken at once in order (the later of a reset and a pose wins), the worker's waits (woken by
// what they wait for, by stop(), or timing out) and the local map's resend flag. Plain values stand in for
// the messages: no ROS.
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "hglasm_odometry/ros/input_queue.h"

namespace hglasm_odometry {
namespace {

using Queue = InputQueue<int, double, float, std::string>;
using Clock = std::chrono::steady_clock;

InputQueueLimits limits(std::size_t scans, std::size_t odometry = 100, std::size_t imu = 100) {
  InputQueueLimits result;
  result.scans = scans;
  result.odometry = odometry;
  result.imu = imu;
  return result;
}

TEST(InputQueue, ScansBeyondTheBoundDropTheOldest) {
  Queue queue(limits(2));
  EXPECT_FALSE(queue.scanCounts().last_arrival.has_value());
  queue.pushScan(1, 10.0);
  queue.pushScan(2, 11.0);
  queue.pushScan(3, 12.0);
  const ScanQueueCounts counts = queue.scanCounts();
  EXPECT_EQ(counts.received, 3u);
  EXPECT_EQ(counts.dropped, 1u);
  EXPECT_EQ(counts.queued, 2u);
  EXPECT_EQ(counts.last_arrival, 12.0);
  EXPECT_EQ(queue.waitForScan(), 2);
  EXPECT_EQ(queue.waitForScan(), 3);
}

TEST(InputQueue, AHeldScanComesBackFirstUnlessTheQueueFilledUp) {
  Queue queue(limits(2));
  queue.pushScan(1, 0.0);
  queue.pushScan(2, 0.0);
  auto scan = queue.waitForScan();
  ASSERT_EQ(scan, 1);
  EXPECT_TRUE(queue.holdScan(*scan, 0.001));
  EXPECT_EQ(queue.waitForScan(), 1);
  EXPECT_EQ(queue.droppedScans(), 0u);

  queue.pushScan(3, 0.0);  // the queue holds 2 and 3: full
  EXPECT_TRUE(queue.holdScan(1, 0.001));
  EXPECT_EQ(queue.droppedScans(), 1u);
  EXPECT_EQ(queue.waitForScan(), 2);
}

TEST(InputQueue, HoldScanWaitsItsTimeWhateverArrives) {
  Queue queue(limits(5));
  const auto start = Clock::now();
  std::thread producer([&queue] {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    queue.pushScan(2, 0.0);
    queue.pushOdometry(1.0, 1.0);
  });
  EXPECT_TRUE(queue.holdScan(1, 0.05));
  producer.join();
  EXPECT_GE(Clock::now() - start, std::chrono::milliseconds(45));
}

TEST(InputQueue, TakeMovesEverythingInOrderAndClearsIt) {
  Queue queue(limits(5, 3));
  Queue::Inputs inputs;
  for (double stamp : {1.0, 2.0, 3.0, 4.0}) queue.pushOdometry(stamp, stamp);  // bound 3: 1.0 dropped
  queue.pushImu(0.5f, 0.5);
  ASSERT_TRUE(queue.take(&inputs));
  ASSERT_EQ(inputs.odometry.size(), 3u);
  EXPECT_EQ(inputs.odometry[0], 2.0);
  EXPECT_EQ(inputs.odometry[2], 4.0);
  ASSERT_EQ(inputs.imu.size(), 1u);
  EXPECT_EQ(inputs.imu.front(), 0.5f);
  EXPECT_FALSE(inputs.reset);
  EXPECT_FALSE(inputs.pose.has_value());

  inputs.odometry.clear();
  inputs.imu.clear();
  ASSERT_TRUE(queue.take(&inputs));
  EXPECT_TRUE(inputs.odometry.empty());
  EXPECT_TRUE(inputs.imu.empty());
  // The queue keeps its bound whichever storage it got back.
  for (double stamp : {5.0, 6.0, 7.0, 8.0}) queue.pushOdometry(stamp, stamp);
  queue.take(&inputs);
  ASSERT_EQ(inputs.odometry.size(), 3u);
  EXPECT_EQ(inputs.odometry.front(), 6.0);
}

TEST(InputQueue, TheLaterOfAResetAndAPoseWins) {
  Queue queue(limits(5));
  Queue::Inputs inputs;
  queue.requestPose("a");
  queue.requestReset();
  queue.take(&inputs);
  EXPECT_TRUE(inputs.reset);
  EXPECT_FALSE(inputs.pose.has_value());

  queue.requestReset();
  queue.requestPose("b");
  queue.take(&inputs);
  EXPECT_FALSE(inputs.reset);
  EXPECT_EQ(inputs.pose, "b");

  queue.take(&inputs);  // taken once
  EXPECT_FALSE(inputs.reset);
  EXPECT_FALSE(inputs.pose.has_value());
}

TEST(InputQueue, WaitForInputsWakesForASampleOrARequest) {
  Queue queue(limits(5));
  const auto far = Clock::now() + std::chrono::seconds(10);
  auto woken = std::async(std::launch::async, [&queue, far] { return queue.waitForInputs(far); });
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  queue.pushOdometry(1.0, 1.0);
  ASSERT_EQ(woken.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_TRUE(woken.get());

  Queue::Inputs inputs;
  queue.take(&inputs);
  woken = std::async(std::launch::async, [&queue, far] { return queue.waitForInputs(far); });
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  queue.requestReset();
  ASSERT_EQ(woken.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_TRUE(woken.get());
}

TEST(InputQueue, WaitForInputsTimesOutWhenOnlyScansArrive) {
  Queue queue(limits(5));
  const auto start = Clock::now();
  std::thread producer([&queue] { queue.pushScan(1, 0.0); });
  EXPECT_FALSE(queue.waitForInputs(start + std::chrono::milliseconds(30)));
  producer.join();
  EXPECT_GE(Clock::now() - start, std::chrono::milliseconds(30));
}

TEST(InputQueue, InputsQueuedBeforeTheWaitEndItAtOnce) {
  Queue queue(limits(5));
  queue.pushImu(1.0f, 1.0);
  EXPECT_TRUE(queue.waitForInputs(Clock::now() + std::chrono::seconds(10)));
}

/// Only the IMU awaited, to 1.0 s.
hglasm::AwaitedStamps imuToOneSecond() {
  hglasm::AwaitedStamps awaited;
  awaited.imu = 1.0;
  return awaited;
}

TEST(InputQueue, AWaitForAStampSleepsThroughTheSamplesBeforeIt) {
  Queue queue(limits(5));
  const auto far = Clock::now() + std::chrono::seconds(10);
  auto woken =
      std::async(std::launch::async, [&queue, far] { return queue.waitForInputs(far, imuToOneSecond()); });
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  for (int i = 0; i < 9; ++i) queue.pushImu(0.0f, 0.1 * i);
  queue.pushOdometry(2.0, 2.0);  // the wheels are not awaited
  // Sleeping through them: a worker woken by any of these would have returned by now.
  EXPECT_EQ(woken.wait_for(std::chrono::milliseconds(50)), std::future_status::timeout);
  queue.pushImu(0.0f, 1.0);
  ASSERT_EQ(woken.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_TRUE(woken.get());
  Queue::Inputs inputs;
  queue.take(&inputs);
  EXPECT_EQ(inputs.imu.size(), 10u);
  EXPECT_EQ(inputs.odometry.size(), 1u);
}

TEST(InputQueue, AWaitForAStampEndsAtOnceForWhatIsQueuedAlreadyNotForWhatWasTaken) {
  Queue queue(limits(5));
  hglasm::AwaitedStamps wheels;
  wheels.wheels = 3.0;
  queue.pushOdometry(3.5, 3.5);  // queued between the worker's take and its wait
  EXPECT_TRUE(queue.waitForInputs(Clock::now() + std::chrono::seconds(10), wheels));
  Queue::Inputs inputs;
  queue.take(&inputs);
  EXPECT_FALSE(queue.waitForInputs(Clock::now() + std::chrono::milliseconds(20), wheels));
  // A sample back in time (a restarted clock) cannot complete the scan's inputs either.
  queue.pushOdometry(0.1, 0.1);
  EXPECT_FALSE(queue.waitForInputs(Clock::now() + std::chrono::milliseconds(20), wheels));
}

TEST(InputQueue, ARequestOrStopEndsAWaitForAStamp) {
  for (const char* ending : {"reset", "pose", "stop"}) {
    Queue queue(limits(5));
    const auto far = Clock::now() + std::chrono::seconds(10);
    auto woken =
        std::async(std::launch::async, [&queue, far] { return queue.waitForInputs(far, imuToOneSecond()); });
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (std::string(ending) == "reset") queue.requestReset();
    if (std::string(ending) == "pose") queue.requestPose("p");
    if (std::string(ending) == "stop") queue.stop();
    ASSERT_EQ(woken.wait_for(std::chrono::seconds(5)), std::future_status::ready) << ending;
    EXPECT_TRUE(woken.get()) << ending;
  }
}

TEST(InputQueue, StopEndsEveryWait) {
  Queue queue(limits(5));
  auto scan = std::async(std::launch::async, [&queue] { return queue.waitForScan(); });
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  queue.stop();
  ASSERT_EQ(scan.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_FALSE(scan.get().has_value());
  // And the later ones at once.
  const auto start = Clock::now();
  EXPECT_FALSE(queue.holdScan(1, 10.0));
  EXPECT_TRUE(queue.waitForInputs(Clock::now() + std::chrono::seconds(10)));
  Queue::Inputs inputs;
  EXPECT_FALSE(queue.take(&inputs));
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(5));
}

TEST(InputQueue, AWaitingWorkerGetsTheScan) {
  Queue queue(limits(5));
  auto scan = std::async(std::launch::async, [&queue] { return queue.waitForScan(); });
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  queue.pushOdometry(1.0, 1.0);  // not what it waits for
  queue.pushScan(7, 0.0);
  ASSERT_EQ(scan.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_EQ(scan.get(), 7);
}

TEST(InputQueue, TheLocalMapRequestIsTakenOnce) {
  Queue queue(limits(5));
  EXPECT_FALSE(queue.takeLocalMapRequest());
  queue.requestLocalMap();
  queue.requestLocalMap();
  EXPECT_TRUE(queue.takeLocalMapRequest());
  EXPECT_FALSE(queue.takeLocalMapRequest());
}

}  // namespace
}  // namespace hglasm_odometry
