#include "hglasm_odometry/tools/evaluation_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/evaluation/map_plot.h"
#include "hglasm_odometry/evaluation/trajectory.h"

namespace hglasm_odometry {
namespace {

/// Where the beam times of a scan came from, for the report.
std::string beamTimesOf(const hglasm::RangeScan& ranges, const hglasm::Scan& scan) {
  if (scan.time_increment == 0.0) return "not known (time_increment and scan/sweep_time are 0)";
  char text[96];
  std::snprintf(text, sizeof text, "%.3g s per beam (%s)", scan.time_increment,
                ranges.time_increment != 0.0 ? "the bag's time_increment" : "scan/sweep_time");
  return text;
}

/// Counts one processed scan into the run.
void record(const ReplayedScan& replayed, std::size_t warnings_kept, EvaluationRun* run) {
  const hglasm::PipelineUpdate& result = replayed.update;
  const hglasm::TrackerUpdate& update = result.tracker;
  const hglasm::TrackerDiagnostics& diagnostics = update.diagnostics;
  ++run->processed;
  run->stale += update.stale;
  run->total_ms.push_back(replayed.cpu_ms);
  run->convert_ms.push_back(result.conversion_cpu_ms);
  if (result.scan_error != hglasm::ScanError::kNone) ++run->conversion_errors;
  if (update.matched) {
    ++run->matched;
    run->prealign_ms.push_back(diagnostics.match.prealign_ms);
    run->refine_ms.push_back(diagnostics.match.refine_ms);
    ++run->statuses[hglasm::toString(diagnostics.match.status)];
  }
  if (update.new_keyframe) run->table_ms.push_back(diagnostics.table_build_ms);
  if (!update.stale) ++run->predictions[hglasm::toString(diagnostics.prediction)];
  run->fallbacks += update.fallback;
  run->deskewed += diagnostics.deskewed;
  run->reanchored += diagnostics.reanchored;
  if (run->beam_times.empty()) run->beam_times = beamTimesOf(replayed.scan->ranges, result.scan);
  run->keyframes += update.new_keyframe;
  run->resets += update.reset && run->processed > 1;  // the first scan starts, it does not reset
  if (!update.warning.empty() && static_cast<std::size_t>(++run->warnings) <= warnings_kept) {
    run->first_warnings.emplace_back(replayed.scan->stamp, update.warning);
  }
  if (update.published) {
    run->trajectory.push_back({replayed.scan->stamp, update.pose});
    run->updates.push_back(update);
  }
}

}  // namespace

std::vector<BagArrival> thinnedArrivals(const BagData& data, double interval, std::size_t* skipped) {
  std::vector<BagArrival> kept;
  double last_kept = -std::numeric_limits<double>::infinity();
  for (const auto& arrival : data.arrivals) {
    if (arrival.scan) {
      const double stamp = data.scans[arrival.index].stamp;
      if (stamp - last_kept < interval) {
        ++*skipped;
        continue;
      }
      last_kept = stamp;
    }
    kept.push_back(arrival);
  }
  return kept;
}

void scoreAtEveryScan(const BagData& data, EvaluationRun* run) {
  const std::vector<hglasm::StampedPose>& published = run->trajectory;
  run->scored.clear();
  run->interpolated = 0;
  std::size_t next = 0;  // the first published pose at or after the scan's stamp
  for (const BagScan& scan : data.scans) {
    while (next < published.size() && published[next].stamp < scan.stamp) ++next;
    if (next < published.size() && published[next].stamp == scan.stamp) {
      run->scored.push_back(published[next]);
    } else if (next > 0 && next < published.size()) {
      const hglasm::StampedPose& before = published[next - 1];
      const hglasm::StampedPose& after = published[next];
      const double t = (scan.stamp - before.stamp) / (after.stamp - before.stamp);
      run->scored.push_back({scan.stamp, hglasm::interpolate(before.pose, after.pose, t)});
      ++run->interpolated;
    }
  }
}

EvaluationRun runEvaluation(const BagData& data, const LaserOdometryOptions& nodelet,
                            const hglasm::TrackerOptions& tracker, double min_scan_interval, double pace_rate,
                            std::size_t warnings_kept) {
  EvaluationRun run;
  hglasm::OdometryPipeline pipeline(tracker, nodelet.odometry_wait > 0.0);
  setLaserMount(data, &pipeline);
  ReplayOptions replay;
  replay.odometry_wait = nodelet.odometry_wait;
  replay.queue_size = static_cast<std::size_t>(nodelet.queue_size);
  replay.pace_rate = pace_rate;
  if (pace_rate > 0.0) replay.rate = pace_rate;  // the waits too are those of a node at that rate
  const auto on_scan = [&](const ReplayedScan& replayed) { record(replayed, warnings_kept, &run); };
  if (min_scan_interval > 0.0) {
    BagData thinned = data;
    thinned.arrivals = thinnedArrivals(data, min_scan_interval, &run.skipped);
    run.replay = replayBag(thinned, &pipeline, replay, on_scan);
  } else {
    run.replay = replayBag(data, &pipeline, replay, on_scan);
  }
  run.inputs = pipeline.inputCounts();
  run.time_offset = pipeline.odometryTimeOffset();
  scoreAtEveryScan(data, &run);
  return run;
}

std::vector<Eigen::Matrix3d> incrementCovariances(const EvaluationRun& run) {
  std::vector<Eigen::Matrix3d> covariances;
  for (const auto& update : run.updates) covariances.push_back(update.increment_covariance);
  return covariances;
}

hglasm::ScanConversionOptions pipelineConversion(const hglasm::TrackerOptions& options, const BagData& data) {
  hglasm::OdometryPipeline pipeline(options);
  setLaserMount(data, &pipeline);
  return pipeline.conversion();
}

std::vector<hglasm::StampedPose> wheelTrajectory(const BagData& data, double shift) {
  hglasm::OdometryBuffer buffer(std::numeric_limits<double>::infinity());
  for (const BagOdometry& sample : data.odometry) buffer.add(sample.stamp, sample.pose);
  std::vector<double> stamps;
  for (const BagScan& scan : data.scans) stamps.push_back(scan.stamp);
  return hglasm::trajectoryAt(buffer, stamps, 0.0, shift);
}

void directPairMotions(const hglasm::TrackerOptions& options, const BagData& data,
                       const std::vector<hglasm::Relation>& relations, double max_span,
                       std::vector<hglasm::Pose2D>* motions, std::vector<bool>* valid) {
  const hglasm::ScanConversionOptions conversion = pipelineConversion(options, data);
  const hglasm::Pose2D mount = data.has_laser_mount ? data.base_to_laser : hglasm::Pose2D();
  const auto scan_at = [&](double stamp) -> const BagScan* {
    const auto it = std::lower_bound(data.scans.begin(), data.scans.end(), stamp - 1e-3,
                                     [](const BagScan& scan, double value) { return scan.stamp < value; });
    return it != data.scans.end() && std::abs(it->stamp - stamp) <= 1e-3 ? &*it : nullptr;
  };
  hglasm::ScanMatcher matcher(options.matcher);
  motions->assign(relations.size(), hglasm::Pose2D());
  valid->assign(relations.size(), false);
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const hglasm::Relation& relation = relations[k];
    if (max_span > 0.0 && std::abs(relation.t2 - relation.t1) > max_span) continue;
    const BagScan* first = scan_at(relation.t1);
    const BagScan* second = scan_at(relation.t2);
    if (!first || !second) continue;
    matcher.setReference(hglasm::scanFromRanges(first->ranges, conversion));
    const hglasm::Pose2D start = mount.inverse() * relation.motion * mount;  // in the laser frame
    const hglasm::MatchResult result =
        matcher.refine(hglasm::scanFromRanges(second->ranges, conversion), start);
    if (result.status != hglasm::MatchStatus::kOk) continue;
    (*motions)[k] = mount * result.pose * mount.inverse();
    (*valid)[k] = true;
  }
}

bool writeScanMap(const std::string& png, const std::string& title, const BagData& data,
                  const hglasm::ScanConversionOptions& conversion,
                  const std::vector<hglasm::StampedPose>& laser_trajectory,
                  const std::vector<hglasm::StampedPose>& wheel_trajectory, std::string* error) {
  std::vector<double> stamps;
  std::vector<std::vector<Eigen::Vector2d>> scans;
  for (const BagScan& scan : data.scans) {
    stamps.push_back(scan.stamp);
    scans.push_back(hglasm::scanFromRanges(scan.ranges, conversion).points);
  }
  const hglasm::Pose2D mount = data.has_laser_mount ? data.base_to_laser : hglasm::Pose2D();
  hglasm::MapPlotOptions options;
  options.title = title;
  return hglasm::writeMapPlot(png, scans,
                              hglasm::laserAndWheelViews(stamps, laser_trajectory, wheel_trajectory, mount),
                              options, error);
}

}  // namespace hglasm_odometry
