// What the subscription callbacks and services hand to the laser odometry's worker thread, and every wait of
// that worker: one mutex and one condition variable. Producers only append (never wait on the worker's
// matching) and wake the worker only for what it waits for (a scan, or the wheel or IMU sample that makes a
// scan's inputs complete), not for every wheel or IMU sample: a 200 Hz IMU waited for to the end of a scan's
// sweep would otherwise wake it once per sample until then. Each wait ends as soon as stop() is called, so
// unloading never waits out a timeout. ROS-free: the element types are the caller's (message pointers in the
// node, plain values in the tests).
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>
#include <optional>
#include <utility>

#include "hglasm_odometry/core/awaited_stamps.h"
#include "hglasm_odometry/ros/ring_buffer.h"

namespace hglasm_odometry {

/// The input queue's bounds: elements kept before the oldest is dropped.
struct InputQueueLimits {
  /// queue_size; the oldest scan is dropped first, the least useful one to a live estimate.
  std::size_t scans = 5;
  std::size_t odometry = 10000;  ///< only reached while the worker waits for tf (100 s at 100 Hz)
  std::size_t imu = 20000;       ///< 20 s at 1 kHz
};

/// The scan side of the queue, for the diagnostics.
struct ScanQueueCounts {
  std::uint64_t received = 0;
  std::uint32_t dropped = 0;  ///< the oldest scan dropped because the queue was full
  std::size_t queued = 0;
  std::optional<double> last_arrival;  ///< `now` of the newest pushScan
};

template <typename Scan, typename Odometry, typename Imu, typename Pose>
class InputQueue {
 public:
  /// What the worker takes at once: the samples queued since the last take, oldest first, and a requested
  /// restart (from the origin, or from a pose; the later request replaces the earlier one).
  struct Inputs {
    RingBuffer<Odometry> odometry;
    RingBuffer<Imu> imu;
    bool reset = false;
    std::optional<Pose> pose;
  };

  explicit InputQueue(const InputQueueLimits& limits)
      : scans_(limits.scans), odometry_(limits.odometry), imu_(limits.imu) {}

  // ---- producers (any thread)

  /// Queues a scan received at `now` (seconds, any clock the caller keeps); when full, drops the oldest
  /// one and counts it.
  void pushScan(Scan scan, double now) {
    bool wake = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (scans_.push_back(std::move(scan))) ++dropped_scans_;
      ++received_scans_;
      last_arrival_ = now;
      wake = waiting_for_ == Wait::kScan;
    }
    if (wake) wake_.notify_one();
  }

  /// Queues a wheel (IMU) sample stamped `stamp` (seconds, the stamps' clock).
  void pushOdometry(Odometry sample, double stamp) {
    pushSample(&odometry_, &odometry_feed_, std::move(sample), stamp);
  }
  void pushImu(Imu sample, double stamp) { pushSample(&imu_, &imu_feed_, std::move(sample), stamp); }

  /// Restart from the origin at the next scan; replaces a requested pose.
  void requestReset() {
    bool wake = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      reset_ = true;
      pose_.reset();
      wake = waiting_for_ == Wait::kInputs;
    }
    if (wake) wake_.notify_one();
  }

  /// Restart from `pose` at the next scan; replaces a requested reset.
  void requestPose(Pose pose) {
    bool wake = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      pose_ = std::move(pose);
      reset_ = false;
      wake = waiting_for_ == Wait::kInputs;
    }
    if (wake) wake_.notify_one();
  }

  /// Send the local map again with the next scan (a subscriber connected). Needs no wake-up.
  void requestLocalMap() {
    std::lock_guard<std::mutex> lock(mutex_);
    local_map_requested_ = true;
  }

  /// Ends every wait of the worker, now and later.
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
  }

  // ---- the worker

  /// The oldest scan, once there is one; nothing once stopped.
  std::optional<Scan> waitForScan() {
    std::unique_lock<std::mutex> lock(mutex_);
    waiting_for_ = Wait::kScan;
    wake_.wait(lock, [this] { return stop_ || !scans_.empty(); });
    waiting_for_ = Wait::kStop;
    if (stop_) return std::nullopt;
    std::optional<Scan> scan(std::move(scans_.front()));
    scans_.pop_front();
    return scan;
  }

  /// Puts back a scan that cannot be processed yet, as the oldest one (dropped and counted instead if
  /// the queue filled up meanwhile), then waits `seconds`. False once stopped.
  bool holdScan(Scan scan, double seconds) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!scans_.push_front(std::move(scan))) ++dropped_scans_;
    wake_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return stop_; });
    return !stop_;
  }

  /// Waits until a sample `awaited` asks for (queued since the last take() or arriving now) or a request is
  /// queued, or stop() (true), or until `deadline` (false). Samples stamped before the awaited stamps (a
  /// new timeline's included) cannot make the scan's inputs complete: they are only queued.
  bool waitForInputs(std::chrono::steady_clock::time_point deadline,
                     const hglasm::AwaitedStamps& awaited = hglasm::AwaitedStamps::anySample()) {
    std::unique_lock<std::mutex> lock(mutex_);
    waiting_for_ = Wait::kInputs;
    awaited_ = awaited;
    const bool woken = wake_.wait_until(lock, deadline, [this] { return stop_ || awaitedArrived(); });
    waiting_for_ = Wait::kStop;
    return woken;
  }

  /// Moves what is queued into `inputs` (its sample buffers empty: their storage goes back to the queue,
  /// so taking allocates nothing) and clears it here. False once stopped.
  bool take(Inputs* inputs) {
    std::lock_guard<std::mutex> lock(mutex_);
    odometry_.swapElements(inputs->odometry);
    imu_.swapElements(inputs->imu);
    odometry_feed_.taken();
    imu_feed_.taken();
    inputs->reset = std::exchange(reset_, false);
    inputs->pose = std::move(pose_);
    pose_.reset();
    return !stop_;
  }

  /// Whether requestLocalMap() was called since the last time this was asked.
  bool takeLocalMapRequest() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(local_map_requested_, false);
  }

  ScanQueueCounts scanCounts() const {
    std::lock_guard<std::mutex> lock(mutex_);
    ScanQueueCounts counts;
    counts.received = received_scans_;
    counts.dropped = dropped_scans_;
    counts.queued = scans_.size();
    counts.last_arrival = last_arrival_;
    return counts;
  }

  std::uint32_t droppedScans() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_scans_;
  }

 private:
  /// What the worker waits for; anything else is only queued (stop() always wakes it).
  enum class Wait { kStop, kScan, kInputs };

  /// The newest stamp of one kind of sample queued since the last take().
  struct Feed {
    double newest_queued = -std::numeric_limits<double>::infinity();

    void push(double stamp) { newest_queued = std::max(newest_queued, stamp); }
    void taken() { newest_queued = -std::numeric_limits<double>::infinity(); }
    bool reaches(double awaited) const { return newest_queued >= awaited; }
  };

  template <typename Sample>
  void pushSample(RingBuffer<Sample>* samples, Feed* feed, Sample sample, double stamp) {
    bool wake = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      samples->push_back(std::move(sample));
      feed->push(stamp);
      wake = waiting_for_ == Wait::kInputs && awaitedArrived();
    }
    if (wake) wake_.notify_one();
  }

  bool awaitedArrived() const {
    return reset_ || pose_.has_value() || (!odometry_.empty() && odometry_feed_.reaches(awaited_.wheels)) ||
           (!imu_.empty() && imu_feed_.reaches(awaited_.imu));
  }

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  RingBuffer<Scan> scans_;
  RingBuffer<Odometry> odometry_;
  RingBuffer<Imu> imu_;
  Feed odometry_feed_, imu_feed_;
  hglasm::AwaitedStamps awaited_;
  std::uint64_t received_scans_ = 0;
  std::uint32_t dropped_scans_ = 0;
  std::optional<double> last_arrival_;
  bool reset_ = false;
  std::optional<Pose> pose_;
  bool local_map_requested_ = false;
  bool stop_ = false;
  Wait waiting_for_ = Wait::kStop;
};

}  // namespace hglasm_odometry
