#include "hglasm_odometry/ros/diagnostics.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <sstream>

namespace hglasm_odometry {
namespace {

/// The window's figures: scans that should have given a laser estimate, of them those that fell back to
/// the prediction, CPU and rate.
struct WindowFigures {
  std::size_t count = 0;
  double cpu_mean = 0.0;
  double cpu_max = 0.0;
  std::size_t matched = 0;  // a failed match counts, and so does an empty or all-invalid scan
  std::size_t failed = 0;
  double rate = 0.0;  // processed scans per second over the window (what the robot's computer sustains)
  double failure_ratio = 0.0;
};

WindowFigures windowFigures(const RingBuffer<ScanRecord>& records, double now, double window) {
  WindowFigures figures;
  double cpu_sum = 0.0, first = 0.0, last = 0.0;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const ScanRecord& record = records[i];
    if (now - record.time > window) continue;
    if (figures.count++ == 0) first = record.time;
    last = record.time;
    cpu_sum += record.cpu_ms;
    figures.cpu_max = std::max(figures.cpu_max, record.cpu_ms);
    if (record.matched || record.fallback) ++figures.matched;
    if (record.fallback) ++figures.failed;
  }
  const double span = figures.count >= 2 ? last - first : 0.0;
  figures.rate = span > 0.0 ? (figures.count - 1) / span : 0.0;
  figures.cpu_mean = figures.count > 0 ? cpu_sum / figures.count : 0.0;
  figures.failure_ratio = figures.matched > 0 ? static_cast<double>(figures.failed) / figures.matched : 0.0;
  return figures;
}

/// As diagnostic_updater's DiagnosticStatusWrapper::add formats a value (operator<<).
template <typename T>
void add(DiagnosticsReport* report, const std::string& key, const T& value) {
  std::ostringstream text;
  text << value;
  report->values.emplace_back(key, text.str());
}

void addValues(const WorkerStatistics& worker, const ScanQueueCounts& scans,
               const DiagnosticsSettings& settings, const WindowFigures& figures, DiagnosticsReport* report) {
  add(report, "scan rate (Hz)", figures.rate);
  add(report, "CPU per scan, mean (ms)", figures.cpu_mean);
  add(report, "CPU per scan, max (ms)", figures.cpu_max);
  add(report, "failure ratio", figures.failure_ratio);
  add(report, "scans received", scans.received);
  add(report, "scans processed", worker.processed);
  add(report, "fallbacks", worker.fallbacks);
  add(report, "resets", worker.resets);
  add(report, "clock jumps back (resets)", worker.input_counts.jumps_back);
  add(report, "dropped scans", scans.dropped);
  add(report, "stale scans dropped", worker.input_counts.stale_scans);
  add(report, "stale odometry samples dropped", worker.input_counts.stale_odometry);
  if (settings.use_imu) add(report, "stale IMU samples dropped", worker.input_counts.stale_imu);
  if (settings.use_odometry) {
    add(report, "odometry time offset (s)", worker.time_offset);
    add(report, "odometry time offset, estimate (s)", worker.time_offset_estimate);
    add(report, "odometry time offset", settings.time_offset_learned ? "learned" : "fixed");
  }
  add(report, "degeneracy of the last match (min / max information)", worker.degeneracy);
  const Eigen::Vector3d& weakest = worker.weakest_direction;
  add(report, "weakest direction of the last match (x, y, theta)",
      std::to_string(weakest.x()) + ", " + std::to_string(weakest.y()) + ", " + std::to_string(weakest.z()));
  add(report, "wheel noise scale learned (xy, theta)",
      std::to_string(worker.noise_scale.xy) + ", " + std::to_string(worker.noise_scale.theta));
  add(report, "queued scans", scans.queued);
  add(report, "preset", settings.preset);
  if (settings.use_imu) {
    add(report, "IMU", worker.imu_stale ? "stale: rotation predicted without it" : "in use");
  }
}

/// printf into a std::string (the summaries diagnostic_updater's summaryf formatted).
std::string format(const char* pattern, ...) {
  char text[256];
  va_list args;
  va_start(args, pattern);
  std::vsnprintf(text, sizeof text, pattern, args);
  va_end(args);
  return text;
}

/// The first problem found, in order of how much it says about the odometry; "tracking" if none.
void summarize(const WorkerStatistics& worker, const ScanQueueCounts& scans,
               const DiagnosticsSettings& settings, const WindowFigures& figures, double now,
               std::uint32_t last_reported_drops, DiagnosticsReport* report) {
  using Level = DiagnosticsReport::Level;
  const DiagnosticsOptions& thresholds = settings.thresholds;
  const auto set = [report](Level level, std::string summary) {
    report->level = level;
    report->summary = std::move(summary);
  };
  const bool scans_arriving = scans.last_arrival && now - *scans.last_arrival <= thresholds.window;
  if (worker.tf_wait) {
    set(Level::kWarn, *worker.tf_wait);
  } else if (!scans_arriving) {
    set(Level::kWarn, scans.last_arrival ? "no scans received recently" : "no scans received yet");
  } else if (figures.matched > 0 && figures.failure_ratio >= thresholds.error_failure_ratio) {
    set(Level::kError, format("%.0f%% of scans failed to match", 100.0 * figures.failure_ratio));
  } else if (figures.matched > 0 && figures.failure_ratio >= thresholds.warn_failure_ratio) {
    set(Level::kWarn, format("%.0f%% of scans failed to match", 100.0 * figures.failure_ratio));
  } else if (settings.use_imu && worker.imu_stale) {
    set(Level::kWarn, "IMU stale or missing: rotation predicted without it");
  } else if (scans.dropped > last_reported_drops) {
    set(Level::kWarn, format("dropping scans: %u dropped so far (processing is slower than the input)",
                             static_cast<unsigned>(scans.dropped)));
  } else if (thresholds.min_rate > 0.0 && figures.rate < thresholds.min_rate) {
    set(Level::kWarn, format("scan rate %.2f Hz below %.2f Hz", figures.rate, thresholds.min_rate));
  } else {
    set(Level::kOk, "tracking");
  }
}

}  // namespace

void WorkerStatistics::add(const ScanRecord& record, const hglasm::TrackerUpdate& update,
                           const hglasm::InputCounts& counts, double window) {
  input_counts = counts;
  time_offset = update.diagnostics.odometry_time_offset;
  time_offset_estimate = update.diagnostics.odometry_time_offset_estimate;
  if (update.matched) {
    degeneracy = update.diagnostics.degeneracy;
    weakest_direction = update.diagnostics.weakest_direction;
  }
  noise_scale = update.diagnostics.learned.wheel_noise;
  if (update.stale) return;  // not processed: not a scan of the rate or failure statistics
  ++processed;
  if (update.fallback) ++fallbacks;
  if (update.reset) ++resets;
  records.push_back(record);
  while (!records.empty() && record.time - records.front().time > window) records.pop_front();
}

DiagnosticsReport diagnose(const WorkerStatistics& worker, const ScanQueueCounts& scans,
                           const DiagnosticsSettings& settings, double now,
                           std::uint32_t last_reported_drops) {
  DiagnosticsReport report;
  const WindowFigures figures = windowFigures(worker.records, now, settings.thresholds.window);
  addValues(worker, scans, settings, figures, &report);
  summarize(worker, scans, settings, figures, now, last_reported_drops, &report);
  return report;
}

}  // namespace hglasm_odometry
