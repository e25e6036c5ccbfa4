// Replays a bag through the odometry pipeline as the nodelet receives it: scans and wheel odometry in the
// bag's order, each scan waiting for its inputs as the nodelet's worker does (the pipeline's feeding
// policy, bounded by odometry/wait), so that a figure of the offline tools is a figure of the nodelet.
#pragma once

#include <cstddef>
#include <functional>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/tools/bag_reader.h"

namespace hglasm_odometry {

struct ReplayOptions {
  /// The nodelet's odometry/wait: wall seconds a scan waits for its inputs (plus the wheels' time
  /// offset when they run late). 0: never wait.
  double odometry_wait = 0.25;
  /// Bag seconds per wall second of the playback being reproduced (rosbag play --rate): a wait of w wall
  /// seconds lasts w * rate seconds of the bag's receive times.
  double rate = 1.0;
  /// The nodelet's queue_size: scans waiting beyond it drop the oldest.
  std::size_t queue_size = 5;
  /// > 0: each scan is processed no earlier (wall clock) than a live worker would turn to it (the bag's
  /// receive times from its first message, divided by this rate, as `rate`): the idle time between scans a
  /// live node has, after which its caches are cold (doc/profile.md, "What idling costs"). 0: as fast as it
  /// goes.
  double pace_rate = 0.0;
};

/// What the replay did with one scan.
struct ReplayedScan {
  const BagScan* scan = nullptr;
  hglasm::PipelineUpdate update;
  double cpu_ms = 0.0;  ///< CPU time of the pipeline's processScan (calling thread)
};

/// Counts of the replay.
struct ReplayCounts {
  std::size_t processed = 0;    ///< scans handed to the pipeline (stale ones included)
  std::size_t queue_drops = 0;  ///< scans dropped by the bounded queue
  std::size_t wait_timeouts = 0;
};

/// Feeds `pipeline` every message of `data.arrivals` (odometry only when the pipeline uses it), calling
/// `on_scan` after each scan it processes. A scan is processed once the pipeline's inputs are ready for it
/// or its wait timed out: by the bag's receive times, a message arriving after the scan's wait would have
/// ended live. At the end of the bag the scans still waiting are processed (their waits time out).
ReplayCounts replayBag(const BagData& data, hglasm::OdometryPipeline* pipeline, const ReplayOptions& options,
                       const std::function<void(const ReplayedScan&)>& on_scan);

}  // namespace hglasm_odometry
