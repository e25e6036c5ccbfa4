// The laser odometry's /diagnostics status as a pure function of what the worker and the input queue
// counted: the same keys, values and summary the node publishes, without ROS (the node copies the report
// into a diagnostic_updater status).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hglasm_odometry/core/motion_model.h"
#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/ros/input_queue.h"
#include "hglasm_odometry/ros/ring_buffer.h"

namespace hglasm_odometry {

/// Thresholds of the /diagnostics status.
struct DiagnosticsOptions {
  double min_rate = 1.0;             ///< Hz: a lower scan rate (while scans arrive) is WARN; 0 disables
  double warn_failure_ratio = 0.2;   ///< fraction of failed matches in the window that is WARN
  double error_failure_ratio = 0.5;  ///< ... that is ERROR
  double window = 10.0;              ///< seconds of statistics behind each status
  double period = 1.0;               ///< seconds between /diagnostics messages (wall clock)
};

/// Its parameters with their valid ranges, for OptionReader and OptionWriter (core/parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, DiagnosticsOptions* options) {
  visitor.nonNegativeNumber("diagnostics/min_rate", &options->min_rate);
  visitor.fraction("diagnostics/warn_failure_ratio", &options->warn_failure_ratio);
  visitor.fraction("diagnostics/error_failure_ratio", &options->error_failure_ratio);
  visitor.positiveNumber("diagnostics/window", &options->window);
  visitor.positiveNumber("diagnostics/period", &options->period);
}

/// One scan processed (not a stale one), for the window of statistics.
struct ScanRecord {
  double time = 0.0;  ///< when it was done (seconds, the clock `now` is on)
  double cpu_ms = 0.0;
  bool matched = false;
  bool fallback = false;
};

/// What the worker knows, as of its last scan.
struct WorkerStatistics {
  RingBuffer<ScanRecord> records;  ///< newest last; those older than the window are ignored
  std::uint64_t processed = 0;
  std::uint64_t fallbacks = 0;
  std::uint64_t resets = 0;
  hglasm::InputCounts input_counts;  ///< the time policy's
  double time_offset = 0.0;          ///< the wheels' time offset in use, and its estimate
  double time_offset_estimate = 0.0;
  double degeneracy = 0.0;  ///< of the last match's scan information, and its weakest direction
  Eigen::Vector3d weakest_direction = Eigen::Vector3d::Zero();
  hglasm::MotionNoiseScale noise_scale;  ///< the wheels' learned so far
  /// Set while scans are held for lack of a usable base -> laser transform: the summary then.
  std::optional<std::string> tf_wait;
  bool imu_stale = false;  ///< use_imu, and the last scan's rotation did not come from the IMU

  /// Counts a scan the worker processed at `record.time`, with the time policy's counts after it; forgets
  /// records older than `window` seconds.
  void add(const ScanRecord& record, const hglasm::TrackerUpdate& update, const hglasm::InputCounts& counts,
           double window);
};

/// What the configuration adds to the status.
struct DiagnosticsSettings {
  DiagnosticsOptions thresholds;
  std::string preset;
  bool use_odometry = true;
  bool use_imu = false;
  bool time_offset_learned = false;  ///< odometry/time_offset/estimate
};

struct DiagnosticsReport {
  enum class Level { kOk, kWarn, kError };
  Level level = Level::kOk;
  std::string summary;
  std::vector<std::pair<std::string, std::string>> values;  ///< key, value; in the order published
};

/// The status at `now` (the clock of the records and of scans.last_arrival). `last_reported_drops`: the
/// dropped scans counted at the previous report (new drops since are a warning).
DiagnosticsReport diagnose(const WorkerStatistics& worker, const ScanQueueCounts& scans,
                           const DiagnosticsSettings& settings, double now,
                           std::uint32_t last_reported_drops);

}  // namespace hglasm_odometry
