// diagnose(): the keys and values of the status in their order, formatted as diagnostic_updater formats
// them, the window's rate, CPU and failure ratio (older records left out), and which problem the summary
// names first. WorkerStatistics::add: stale scans are not counted, the window is trimmed.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "hglasm_odometry/ros/diagnostics.h"

namespace hglasm_odometry {
namespace {

using Level = DiagnosticsReport::Level;

std::map<std::string, std::string> valuesOf(const DiagnosticsReport& report) {
  return {report.values.begin(), report.values.end()};
}

std::vector<std::string> keysOf(const DiagnosticsReport& report) {
  std::vector<std::string> keys;
  for (const auto& value : report.values) keys.push_back(value.first);
  return keys;
}

/// Scans at 10 Hz from `start` to `end` (seconds), every `fail_every`-th a fallback (0: none).
WorkerStatistics scansAt10Hz(double start, double end, int fail_every = 0) {
  WorkerStatistics worker;
  int index = 0;
  for (double time = start; time <= end + 1e-9; time += 0.1, ++index) {
    ScanRecord record;
    record.time = time;
    record.cpu_ms = index % 2 ? 3.0 : 1.0;
    record.fallback = fail_every > 0 && index % fail_every == 0;
    record.matched = !record.fallback;
    hglasm::TrackerUpdate update;
    update.matched = record.matched;
    update.fallback = record.fallback;
    worker.add(record, update, hglasm::InputCounts(), 10.0);
  }
  return worker;
}

ScanQueueCounts arriving(double last_arrival) {
  ScanQueueCounts scans;
  scans.received = 123;
  scans.queued = 2;
  scans.last_arrival = last_arrival;
  return scans;
}

TEST(Diagnostics, KeysInTheOrderPublished) {
  DiagnosticsSettings settings;
  settings.use_odometry = true;
  settings.use_imu = true;
  const DiagnosticsReport report = diagnose(WorkerStatistics(), ScanQueueCounts(), settings, 0.0, 0);
  const std::vector<std::string> expected = {"scan rate (Hz)",
                                             "CPU per scan, mean (ms)",
                                             "CPU per scan, max (ms)",
                                             "failure ratio",
                                             "scans received",
                                             "scans processed",
                                             "fallbacks",
                                             "resets",
                                             "clock jumps back (resets)",
                                             "dropped scans",
                                             "stale scans dropped",
                                             "stale odometry samples dropped",
                                             "stale IMU samples dropped",
                                             "odometry time offset (s)",
                                             "odometry time offset, estimate (s)",
                                             "odometry time offset",
                                             "degeneracy of the last match (min / max information)",
                                             "weakest direction of the last match (x, y, theta)",
                                             "wheel noise scale learned (xy, theta)",
                                             "queued scans",
                                             "preset",
                                             "IMU"};
  EXPECT_EQ(keysOf(report), expected);

  settings.use_odometry = false;
  settings.use_imu = false;
  const std::vector<std::string> keys =
      keysOf(diagnose(WorkerStatistics(), ScanQueueCounts(), settings, 0.0, 0));
  EXPECT_EQ(keys.size(), expected.size() - 5);  // no IMU key, no stale IMU samples, no time offsets
  for (const std::string& key : keys) EXPECT_EQ(key.find("IMU"), std::string::npos) << key;
}

TEST(Diagnostics, ValuesFormattedAsDiagnosticUpdaterDoes) {
  WorkerStatistics worker = scansAt10Hz(0.0, 9.0);
  worker.degeneracy = 0.125;
  worker.weakest_direction = Eigen::Vector3d(1.0, 0.0, -0.5);
  worker.noise_scale.xy = 1.5;
  worker.noise_scale.theta = 2.0;
  worker.time_offset = 0.02;
  worker.input_counts.stale_odometry = 4;
  DiagnosticsSettings settings;
  settings.preset = "medium";
  settings.time_offset_learned = true;
  ScanQueueCounts scans = arriving(9.0);
  scans.dropped = 3;
  const auto values = valuesOf(diagnose(worker, scans, settings, 9.0, 3));
  EXPECT_EQ(values.at("scan rate (Hz)"), "10");
  EXPECT_EQ(values.at("CPU per scan, mean (ms)"), "1.98901");  // 46 scans of 1 ms, 45 of 3 ms
  EXPECT_EQ(values.at("CPU per scan, max (ms)"), "3");
  EXPECT_EQ(values.at("failure ratio"), "0");
  EXPECT_EQ(values.at("scans received"), "123");
  EXPECT_EQ(values.at("scans processed"), "91");
  EXPECT_EQ(values.at("dropped scans"), "3");
  EXPECT_EQ(values.at("stale odometry samples dropped"), "4");
  EXPECT_EQ(values.at("odometry time offset (s)"), "0.02");
  EXPECT_EQ(values.at("odometry time offset"), "learned");
  EXPECT_EQ(values.at("degeneracy of the last match (min / max information)"), "0.125");
  EXPECT_EQ(values.at("weakest direction of the last match (x, y, theta)"), "1.000000, 0.000000, -0.500000");
  EXPECT_EQ(values.at("wheel noise scale learned (xy, theta)"), "1.500000, 2.000000");
  EXPECT_EQ(values.at("queued scans"), "2");
  EXPECT_EQ(values.at("preset"), "medium");
}

TEST(Diagnostics, OnlyTheWindowCounts) {
  // 20 s of scans, every other one failing in the first 10 s, none after: the window (10 s) sees no failure.
  WorkerStatistics worker = scansAt10Hz(0.0, 9.95, 2);
  const WorkerStatistics later = scansAt10Hz(10.0, 20.0);
  for (std::size_t i = 0; i < later.records.size(); ++i) {
    hglasm::TrackerUpdate update;
    update.matched = true;
    worker.add(later.records[i], update, hglasm::InputCounts(), 1e9);  // nothing trimmed on the way
  }
  const auto values = valuesOf(diagnose(worker, arriving(20.0), DiagnosticsSettings(), 20.0, 0));
  EXPECT_EQ(values.at("failure ratio"), "0");
  EXPECT_EQ(values.at("scan rate (Hz)"), "10");
  const auto earlier = valuesOf(diagnose(worker, arriving(20.0), DiagnosticsSettings(), 12.0, 0));
  EXPECT_NE(earlier.at("failure ratio"), "0");
}

TEST(Diagnostics, AddLeavesStaleScansOutAndTrimsTheWindow) {
  WorkerStatistics worker;
  hglasm::TrackerUpdate update;
  update.matched = true;
  update.diagnostics.degeneracy = 0.3;
  for (int i = 0; i < 30; ++i) {
    ScanRecord record;
    record.time = i;
    worker.add(record, update, hglasm::InputCounts(), 10.0);
  }
  EXPECT_EQ(worker.processed, 30u);
  EXPECT_EQ(worker.records.size(), 11u);  // 19 .. 29 s
  update.stale = true;
  update.diagnostics.degeneracy = 0.7;
  hglasm::InputCounts counts;
  counts.stale_scans = 1;
  ScanRecord record;
  record.time = 30.0;
  worker.add(record, update, counts, 10.0);
  EXPECT_EQ(worker.processed, 30u);
  EXPECT_EQ(worker.records.size(), 11u);
  EXPECT_EQ(worker.input_counts.stale_scans, 1u);
  EXPECT_EQ(worker.degeneracy, 0.7);  // the last match's, stale or not
}

TEST(Diagnostics, TheSummaryNamesTheFirstProblem) {
  DiagnosticsSettings settings;
  settings.use_imu = true;
  WorkerStatistics worker = scansAt10Hz(0.0, 9.0);

  DiagnosticsReport report = diagnose(worker, ScanQueueCounts(), settings, 9.0, 0);
  EXPECT_EQ(report.level, Level::kWarn);
  EXPECT_EQ(report.summary, "no scans received yet");
  report = diagnose(worker, arriving(-1.5), settings, 9.0, 0);
  EXPECT_EQ(report.summary, "no scans received recently");

  report = diagnose(worker, arriving(9.0), settings, 9.0, 0);
  EXPECT_EQ(report.level, Level::kOk);
  EXPECT_EQ(report.summary, "tracking");

  worker.imu_stale = true;
  report = diagnose(worker, arriving(9.0), settings, 9.0, 0);
  EXPECT_EQ(report.summary, "IMU stale or missing: rotation predicted without it");
  worker.imu_stale = false;

  ScanQueueCounts dropping = arriving(9.0);
  dropping.dropped = 7;
  report = diagnose(worker, dropping, settings, 9.0, 5);
  EXPECT_EQ(report.level, Level::kWarn);
  EXPECT_EQ(report.summary, "dropping scans: 7 dropped so far (processing is slower than the input)");
  EXPECT_EQ(diagnose(worker, dropping, settings, 9.0, 7).summary, "tracking");  // reported already

  settings.thresholds.min_rate = 20.0;
  EXPECT_EQ(diagnose(worker, arriving(9.0), settings, 9.0, 0).summary, "scan rate 10.00 Hz below 20.00 Hz");

  worker.tf_wait = "waiting for tf base_link -> laser";
  report = diagnose(worker, ScanQueueCounts(), settings, 9.0, 0);
  EXPECT_EQ(report.level, Level::kWarn);
  EXPECT_EQ(report.summary, "waiting for tf base_link -> laser");
}

TEST(Diagnostics, FailedMatchesWarnThenError) {
  DiagnosticsSettings settings;  // WARN from 20 %, ERROR from 50 %
  DiagnosticsReport report = diagnose(scansAt10Hz(0.0, 9.0, 4), arriving(9.0), settings, 9.0, 0);
  EXPECT_EQ(report.level, Level::kWarn);
  EXPECT_EQ(report.summary, "25% of scans failed to match");
  report = diagnose(scansAt10Hz(0.0, 9.0, 2), arriving(9.0), settings, 9.0, 0);
  EXPECT_EQ(report.level, Level::kError);
  EXPECT_EQ(report.summary, "51% of scans failed to match");
}

}  // namespace
}  // namespace hglasm_odometry
