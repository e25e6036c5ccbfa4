#include "hglasm_odometry/tools/bag_replay.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <thread>

#include "hglasm_odometry/core/timing.h"

namespace hglasm_odometry {
namespace {

/// The nodelet's worker over a bag: a FIFO of scans, each waiting for its inputs from when the worker
/// turns to it (its arrival, or the end of the previous scan's wait).
class Replay {
 public:
  Replay(const BagData& data, hglasm::OdometryPipeline* pipeline, const ReplayOptions& options,
         const std::function<void(const ReplayedScan&)>& on_scan)
      : data_(data), pipeline_(pipeline), options_(options), on_scan_(on_scan) {}

  ReplayCounts run() {
    const bool use_odometry = pipeline_->options().prediction.use_odometry;
    wall_start_ = std::chrono::steady_clock::now();
    if (!data_.arrivals.empty()) first_receive_time_ = receiveTime(data_.arrivals.front());
    for (const BagArrival& arrival : data_.arrivals) {
      const double now = receiveTime(arrival);
      timeOut(now);
      if (arrival.scan) {
        enqueue(&data_.scans[arrival.index], now);
      } else if (use_odometry) {
        const BagOdometry& sample = data_.odometry[arrival.index];
        pipeline_->addOdometry(sample.stamp, sample.pose);
      }
      processReady(now);
    }
    timeOut(std::numeric_limits<double>::infinity());
    return counts_;
  }

 private:
  void enqueue(const BagScan* scan, double now) {
    // The front scan is the worker's (out of the queue); behind it the queue drops its oldest.
    if (waiting_.size() > std::max<std::size_t>(1, options_.queue_size)) {
      waiting_.erase(waiting_.begin() + 1);
      ++counts_.queue_drops;
    }
    waiting_.push_back(scan);
    if (waiting_.size() == 1) wait_start_ = std::max(wait_start_, now);
  }

  /// The wall wait of the front scan, in bag seconds.
  double waitLength() const {
    if (!(options_.odometry_wait > 0.0)) return 0.0;
    return (options_.odometry_wait + std::max(0.0, pipeline_->odometryTimeOffset())) * options_.rate;
  }

  /// Scans whose wait ended before `now` go on with what has arrived.
  void timeOut(double now) {
    while (!waiting_.empty()) {
      const double deadline = wait_start_ + waitLength();
      if (!(now > deadline)) break;
      if (!pipeline_->inputsReadyFor(waiting_.front()->stamp, sweep(*waiting_.front()))) {
        pipeline_->inputsWaitTimedOut(waiting_.front()->stamp, sweep(*waiting_.front()));
        ++counts_.wait_timeouts;
      }
      processFront(deadline);
    }
  }

  void processReady(double now) {
    while (!waiting_.empty() &&
           pipeline_->inputsReadyFor(waiting_.front()->stamp, sweep(*waiting_.front()))) {
      processFront(now);
    }
  }

  double receiveTime(const BagArrival& arrival) const {
    return arrival.scan ? data_.scans[arrival.index].receive_time
                        : data_.odometry[arrival.index].receive_time;
  }

  /// With options_.pace_rate, sleeps until `now` (bag seconds: when a live worker turns to the scan, its
  /// inputs there or its wait over) comes at that playback rate.
  void pace(double now) const {
    if (!(options_.pace_rate > 0.0) || !std::isfinite(now)) return;
    const std::chrono::duration<double> since_start((now - first_receive_time_) / options_.pace_rate);
    std::this_thread::sleep_until(
        wall_start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(since_start));
  }

  double sweep(const BagScan& scan) const {
    return hglasm::scanSweepTime(scan.ranges.time_increment, scan.ranges.ranges.size(),
                                 pipeline_->conversion());
  }

  void processFront(double now) {
    ReplayedScan replayed;
    replayed.scan = waiting_.front();
    waiting_.pop_front();
    pace(now);
    const double start = hglasm::threadCpuMs();
    replayed.update = pipeline_->processScan(replayed.scan->stamp, replayed.scan->ranges);
    replayed.cpu_ms = hglasm::threadCpuMs() - start;
    ++counts_.processed;
    wait_start_ = now;  // the worker turns to the next scan
    on_scan_(replayed);
  }

  const BagData& data_;
  hglasm::OdometryPipeline* pipeline_;
  const ReplayOptions& options_;
  const std::function<void(const ReplayedScan&)>& on_scan_;
  std::deque<const BagScan*> waiting_;
  double wait_start_ = -std::numeric_limits<double>::infinity();
  std::chrono::steady_clock::time_point wall_start_;
  double first_receive_time_ = 0.0;
  ReplayCounts counts_;
};

}  // namespace

ReplayCounts replayBag(const BagData& data, hglasm::OdometryPipeline* pipeline, const ReplayOptions& options,
                       const std::function<void(const ReplayedScan&)>& on_scan) {
  return Replay(data, pipeline, options, on_scan).run();
}

}  // namespace hglasm_odometry
