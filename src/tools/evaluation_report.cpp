#include "hglasm_odometry/tools/evaluation_report.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/evaluation/statistics.h"
#include "hglasm_odometry/evaluation/trajectory.h"

namespace hglasm_odometry {
namespace {

/// The five largest short laser errors beside the wheels' and the largest leap ratio over all of them.
void worstRelations(const std::vector<hglasm::Relation>& relations,
                    const std::vector<hglasm::StampedPose>& trajectory,
                    const std::vector<hglasm::StampedPose>& wheel_trajectory, RelationsReport* report) {
  std::vector<hglasm::RelationError> laser =
      hglasm::relationErrors(relations, trajectory, report->short_span);
  std::map<std::size_t, hglasm::RelationError> wheel_by_index;
  for (const auto& error : hglasm::relationErrors(relations, wheel_trajectory, report->short_span)) {
    wheel_by_index[error.index] = error;
  }
  for (const auto& error : laser) {
    const auto it = wheel_by_index.find(error.index);
    if (it == wheel_by_index.end()) continue;
    const double ratio = error.trans() / (3.0 * it->second.trans() + 0.10);
    if (ratio <= report->worst_leap_ratio) continue;
    report->worst_leap_ratio = ratio;
    const hglasm::Relation& relation = relations[error.index];
    report->worst_leap = WorstRelation{relation.t1, relation.t2 - relation.t1, error, true, it->second};
  }
  std::sort(laser.begin(), laser.end(), [](const auto& a, const auto& b) { return a.trans() > b.trans(); });
  for (std::size_t k = 0; k < std::min<std::size_t>(5, laser.size()); ++k) {
    WorstRelation worst;
    const hglasm::Relation& relation = relations[laser[k].index];
    worst.t1 = relation.t1;
    worst.span = relation.t2 - relation.t1;
    worst.laser = laser[k];
    const auto it = wheel_by_index.find(laser[k].index);
    worst.has_wheel = it != wheel_by_index.end();
    if (worst.has_wheel) worst.wheel = it->second;
    report->worst.push_back(worst);
  }
}

void printStatsRows(std::FILE* out, const char* label, const hglasm::RelationStats& laser,
                    const hglasm::RelationStats& wheel, bool has_wheel) {
  std::fprintf(out, "  %-9s %5d %7d | %.4f +- %.4f  %6.3f +- %6.3f", label, laser.count, laser.missing,
               laser.trans_mean, laser.trans_std, laser.rot_mean_deg, laser.rot_std_deg);
  if (has_wheel) {
    std::fprintf(out, " | %.4f +- %.4f  %6.3f +- %6.3f", wheel.trans_mean, wheel.trans_std,
                 wheel.rot_mean_deg, wheel.rot_std_deg);
  }
  std::fprintf(out, "\n  %-9s %13s | median %.4f m  %6.3f deg    ", "", "", laser.trans_median,
               laser.rot_median_deg);
  if (has_wheel) std::fprintf(out, " | median %.4f m  %6.3f deg", wheel.trans_median, wheel.rot_median_deg);
  std::fprintf(out, "\n  %-9s %13s | sq %.6f m2  %9.4f deg2", "", "", laser.trans_sq_mean,
               laser.rot_sq_mean_deg);
  if (has_wheel) std::fprintf(out, " | sq %.6f m2  %9.4f deg2", wheel.trans_sq_mean, wheel.rot_sq_mean_deg);
  std::fprintf(out, "\n  %-9s %13s | along-track scale %.4f +- %.4f (%d)", "", "", laser.along_track_scale,
               laser.along_track_scale_error, laser.along_track_count);
  if (has_wheel) {
    std::fprintf(out, " | along-track scale %.4f +- %.4f (%d)", wheel.along_track_scale,
                 wheel.along_track_scale_error, wheel.along_track_count);
  }
  std::fprintf(out, "\n");
}

/// The fusion line: how often the prediction was doubted, leaps, search sizes, the wheel noise learned.
void printFusion(std::FILE* out, const EvaluationRun& run) {
  int rejected = 0, doubted = 0, leaps = 0, small_searches = 0;
  double map_keyframes = 0.0;
  const int small_population = hglasm::presetOptions(hglasm::Preset::kSmall).genetic.population;
  for (const auto& update : run.updates) {
    rejected += update.diagnostics.jump_rejected;
    doubted += update.diagnostics.prediction_doubted;
    leaps += update.leap;
    if (update.matched) {
      small_searches += update.diagnostics.search.population <= small_population;
      map_keyframes += update.diagnostics.map_keyframes;
    }
  }
  const hglasm::LearnedModels last =
      run.updates.empty() ? hglasm::LearnedModels() : run.updates.back().diagnostics.learned;
  std::fprintf(out,
               "\nfusion        prediction doubted %d times: %d leaps taken, %d rejected; %d of %d searches "
               "small-sized, %.1f keyframes per map; wheel noise scale learned: xy %.3g, theta %.3g; scan "
               "noise scale (weakest, middle, strongest direction) %.3g, %.3g, %.3g",
               doubted, leaps, rejected, small_searches, run.matched,
               run.matched ? map_keyframes / run.matched : 0.0, last.wheel_noise.xy, last.wheel_noise.theta,
               last.scan_noise[0], last.scan_noise[1], last.scan_noise[2]);
  std::fprintf(
      out,
      "\nwheels        systematic errors learned: turn scale %+.4f, heading %+.3f deg/m, distance scale "
      "%+.4f; the laser sits (%+.3f, %+.3f) m from its mount",
      last.wheel_turn_scale, last.wheel_heading_per_metre * hglasm::kRadToDeg, last.wheel_distance_scale,
      last.laser_offset.x(), last.laser_offset.y());
}

/// CPU (and wall) time per stage: median, p99, max and the mean per scan.
void printTimes(std::FILE* out, const EvaluationRun& run, double data_seconds) {
  const std::size_t scans = run.processed;
  std::fprintf(out, "\n\nms per scan                     scans   median      p99      max  mean/scan\n");
  const auto row = [out, scans](const char* label, const hglasm::Spread& spread) {
    std::fprintf(out, "  %-29s %6zu %8.3f %8.3f %8.3f %8.3f\n", label, spread.count, spread.median,
                 spread.p99, spread.max, scans ? spread.mean * spread.count / scans : 0.0);
  };
  row("scan conversion (CPU)", hglasm::spreadOf(run.convert_ms));
  row("table build, keyframes (wall)", hglasm::spreadOf(run.table_ms));
  row("pre-align GA (wall)", hglasm::spreadOf(run.prealign_ms));
  row("refine MbICP (wall)", hglasm::spreadOf(run.refine_ms));
  const hglasm::Spread total = hglasm::spreadOf(run.total_ms);
  row("total per scan (CPU)", total);
  const double cpu_seconds = total.mean * scans * 1e-3;
  std::fprintf(out, "  total = conversion + OdometryTracker::processScan (incl. table builds), one thread\n");
  std::fprintf(out, "  total CPU %.2f s for %.1f s of data: %.0fx real time\n", cpu_seconds, data_seconds,
               cpu_seconds > 0.0 ? data_seconds / cpu_seconds : 0.0);
}

/// Per-relation motions of one estimate (valid[k]: relation k's stamps are in it).
struct RelativeMotions {
  std::vector<hglasm::Pose2D> motions;
  std::vector<bool> valid;
};

RelativeMotions relativeMotionsOf(const std::vector<hglasm::Relation>& relations,
                                  const std::vector<hglasm::StampedPose>& trajectory) {
  RelativeMotions result;
  hglasm::relativeMotions(relations, trajectory, &result.motions, &result.valid);
  return result;
}

/// The short relations the scans and the wheels agree against, and the metric without them.
void judgeReference(const std::vector<hglasm::Relation>& relations, const EvaluationRun& run,
                    const std::vector<hglasm::StampedPose>& wheel_trajectory, const RelativeMotions& wheels,
                    const RelativeMotions& direct, RelationsReport* report) {
  const std::vector<bool> contradicted = hglasm::contradictedRelations(
      relations, direct.motions, direct.valid, wheels.motions, wheels.valid, report->short_span,
      RelationsReport::kContradiction, RelationsReport::kAgreement);
  std::vector<hglasm::Relation> rest;
  for (std::size_t k = 0; k < relations.size(); ++k) {
    if (contradicted[k]) {
      ++report->contradicted;
    } else {
      rest.push_back(relations[k]);
    }
  }
  report->laser_short_uncontradicted = hglasm::evaluateRelations(rest, run.scored, report->short_span);
  report->wheel_short_uncontradicted = hglasm::evaluateRelations(rest, wheel_trajectory, report->short_span);
  report->calibration_uncontradicted =
      hglasm::evaluateCalibration(rest, run.trajectory, incrementCovariances(run), report->short_span);
}

}  // namespace

RelationsReport evaluateRun(const std::vector<hglasm::Relation>& relations, const EvaluationRun& run,
                            const std::vector<hglasm::StampedPose>& wheel_trajectory, const BagData& data,
                            double short_span, const hglasm::TrackerOptions* direct_pairs_options) {
  RelationsReport report;
  report.short_span = short_span;
  report.laser_all = hglasm::evaluateRelations(relations, run.scored, 0.0);
  report.wheel_all = hglasm::evaluateRelations(relations, wheel_trajectory, 0.0);
  report.laser_short = hglasm::evaluateRelations(relations, run.scored, short_span);
  report.wheel_short = hglasm::evaluateRelations(relations, wheel_trajectory, short_span);
  // The reference relations come from aligning scans, so they may describe the laser's motion.
  report.laser_frame = data.has_laser_mount && !(data.base_to_laser.translationNorm() < 1e-9 &&
                                                 std::abs(data.base_to_laser.theta) < 1e-9);
  report.laser_frame_short = report.laser_short;
  if (report.laser_frame) {
    const auto laser = hglasm::followedBy(run.scored, data.base_to_laser);
    const auto wheel = hglasm::followedBy(wheel_trajectory, data.base_to_laser);
    report.laser_frame_all = hglasm::evaluateRelations(relations, laser, 0.0);
    report.wheel_laser_frame_all = hglasm::evaluateRelations(relations, wheel, 0.0);
    report.laser_frame_short = hglasm::evaluateRelations(relations, laser, short_span);
    report.wheel_laser_frame_short = hglasm::evaluateRelations(relations, wheel, short_span);
  }
  // Turn rates from the wheels where there are any: their timing is the bag's, not the fusion's.
  const std::vector<hglasm::StampedPose>& turn_rates =
      wheel_trajectory.empty() ? run.scored : wheel_trajectory;
  const auto timing = [&](const RelativeMotions& estimate) {
    return hglasm::fitTimingOffset(relations, estimate.motions, estimate.valid, turn_rates, short_span);
  };
  const RelativeMotions wheels = relativeMotionsOf(relations, wheel_trajectory);
  report.has_timing = true;
  report.laser_timing = timing(relativeMotionsOf(relations, run.scored));
  if (!wheel_trajectory.empty()) report.wheel_timing = timing(wheels);
  if (direct_pairs_options) {
    RelativeMotions direct;
    directPairMotions(*direct_pairs_options, data, relations, short_span, &direct.motions, &direct.valid);
    report.has_direct_pairs = true;
    report.direct_pairs =
        hglasm::evaluateRelativeMotions(relations, direct.motions, direct.valid, short_span);
    report.direct_pairs_timing = timing(direct);
    if (!wheel_trajectory.empty()) judgeReference(relations, run, wheel_trajectory, wheels, direct, &report);
  }
  report.calibration =
      hglasm::evaluateCalibration(relations, run.trajectory, incrementCovariances(run), short_span);
  worstRelations(relations, run.scored, wheel_trajectory, &report);
  return report;
}

void printInputs(std::FILE* out, const EvaluateArguments& args, const EvaluateInputs& inputs,
                 const std::string& preset, bool use_odometry) {
  const BagData& data = inputs.data;
  std::fprintf(out, "bag           %s: %zu scans, %zu odometry samples (read in %.1f s CPU)\n",
               args.bag.c_str(), data.scans.size(), data.odometry.size(), inputs.read_cpu_seconds);
  std::fprintf(out, "laser mount   %s: base '%s' -> laser '%s' = (%.3f, %.3f, %.3f rad)%s\n",
               inputs.mount_source.c_str(), data.base_frame.c_str(),
               data.scans.empty() ? "" : data.scans.front().frame_id.c_str(), data.base_to_laser.x,
               data.base_to_laser.y, data.base_to_laser.theta,
               data.laser_upside_down ? ", upside down (scans mirrored)" : "");
  if (args.odom_stamp_shift != 0.0) {
    std::fprintf(out, "odometry      every message moved %.3f s later (--odom-stamp-shift)\n",
                 args.odom_stamp_shift);
  }
  std::fprintf(out, "options       %s, preset %s, wheel odometry %s\n", args.config.c_str(), preset.c_str(),
               !use_odometry           ? "off"
               : data.odometry.empty() ? "on (but none in the bag)"
                                       : "on");
}

void printRun(std::FILE* out, const EvaluationRun& run, double data_seconds, bool warnings) {
  for (std::size_t i = 0; warnings && i < run.first_warnings.size(); ++i) {
    std::fprintf(out, "  warning at %.6f: %s\n", run.first_warnings[i].first,
                 run.first_warnings[i].second.c_str());
  }
  const std::size_t scans = run.processed;
  if (run.skipped) std::fprintf(out, "\nskipped       %zu scans (--min-scan-interval)", run.skipped);
  std::fprintf(out,
               "\nscans         %zu processed, %d matched, %d keyframes, %d resets after the start, %zu "
               "published\n",
               scans, run.matched, run.keyframes, run.resets, run.trajectory.size());
  std::fprintf(
      out,
      "time policy   %zu stale scans and %llu stale odometry samples dropped, %llu clock jumps back; "
      "%zu scans dropped by the queue, %zu waits for inputs timed out (bag order, 1x playback)\n",
      run.stale, static_cast<unsigned long long>(run.inputs.stale_odometry),
      static_cast<unsigned long long>(run.inputs.jumps_back), run.replay.queue_drops,
      run.replay.wait_timeouts);
  if (run.interpolated) {
    std::fprintf(out,
                 "scored        %zu scans not published are scored at the pose interpolated between the "
                 "published ones around them (what tf gives there)\n",
                 run.interpolated);
  }
  std::fprintf(out, "local map     re-anchored %d times (a scan that did not fit it)\n", run.reanchored);
  std::fprintf(out, "odometry lag  time offset %.3f s in use at the end (odometry/time_offset)\n",
               run.time_offset);
  std::fprintf(out, "fallbacks     %d (%.2f %% of scans), conversion errors %d, warnings %d\n", run.fallbacks,
               scans ? 100.0 * run.fallbacks / scans : 0.0, run.conversion_errors, run.warnings);
  std::fprintf(out, "de-skewed     %d scans; beam times %s\n", run.deskewed, run.beam_times.c_str());
  std::fprintf(out, "match status ");
  for (const auto& entry : run.statuses) std::fprintf(out, " %s %d", entry.first.c_str(), entry.second);
  std::fprintf(out, "\nprediction   ");
  for (const auto& entry : run.predictions) std::fprintf(out, " %s %d", entry.first.c_str(), entry.second);
  printFusion(out, run);
  printTimes(out, run, data_seconds);
}

namespace {

void printContradicted(std::FILE* out, const char* short_label, const RelationsReport& report,
                       bool has_wheel) {
  if (!has_wheel) return;
  const hglasm::RelationStats& laser = report.laser_short_uncontradicted;
  const hglasm::RelationStats& wheel = report.wheel_short_uncontradicted;
  std::fprintf(
      out,
      "  contradicted: %d relations %s whose direct pair settles > %.0f deg from the reference's turn "
      "and within %.0f deg of the wheels'; without them (%d): laser %.4f / %.3f (median %.4f / %.3f), "
      "wheels %.4f / %.3f (median %.4f / %.3f), calibration %.2f\n",
      report.contradicted, short_label, RelationsReport::kContradiction * hglasm::kRadToDeg,
      RelationsReport::kAgreement * hglasm::kRadToDeg, laser.count, laser.trans_mean, laser.rot_mean_deg,
      laser.trans_median, laser.rot_median_deg, wheel.trans_mean, wheel.rot_mean_deg, wheel.trans_median,
      wheel.rot_median_deg, report.calibration_uncontradicted.mean_sq_mahalanobis);
}

void printTiming(std::FILE* out, const char* short_label, const RelationsReport& report, bool has_wheel) {
  const auto print = [&](const char* name, const hglasm::TimingFit& fit) {
    std::fprintf(out, "%s %+.0f +- %.0f ms, turns %+.2f +- %.2f %% (%d)", name, 1e3 * fit.offset,
                 1e3 * fit.offset_sd, 1e2 * fit.turn_scale, 1e2 * fit.turn_scale_sd, fit.count);
  };
  std::fprintf(out,
               "  timing %s: heading error = offset x change of turn rate (wheels') + turn scale x the "
               "reference's turn, of ",
               short_label);
  print("laser", report.laser_timing);
  if (has_wheel) print(", wheels", report.wheel_timing);
  if (report.has_direct_pairs) print(", direct pairs", report.direct_pairs_timing);
  std::fprintf(out, "\n");
}

}  // namespace

void printRelationsReport(std::FILE* out, const std::string& relations_path,
                          const std::vector<hglasm::Relation>& relations, const RelationsReport& report,
                          const std::string& base_frame, bool has_wheel) {
  std::fprintf(out, "\nrelations     %s: %zu (Kümmerle et al. 2009; mean +- std, population)\n",
               relations_path.c_str(), relations.size());
  char short_label[32];
  std::snprintf(short_label, sizeof(short_label), "<= %g s", report.short_span);
  std::fprintf(out, "  %-9s %5s %7s | %-33s", "relations", "n", "missing", "laser odometry: m, deg");
  if (has_wheel) std::fprintf(out, " | %s", "wheel odometry: m, deg");
  std::fprintf(out, "\n  base frame ('%s', the trajectory's)\n", base_frame.c_str());
  printStatsRows(out, "all", report.laser_all, report.wheel_all, has_wheel);
  printStatsRows(out, short_label, report.laser_short, report.wheel_short, has_wheel);
  if (report.laser_frame) {
    std::fprintf(out,
                 "  laser frame (the same trajectories moved to the laser, if the reference describes its "
                 "motion)\n");
    printStatsRows(out, "all", report.laser_frame_all, report.wheel_laser_frame_all, has_wheel);
    printStatsRows(out, short_label, report.laser_frame_short, report.wheel_laser_frame_short, has_wheel);
  }
  if (report.has_direct_pairs) {
    const hglasm::RelationStats& direct = report.direct_pairs;
    std::fprintf(out,
                 "  direct pairs: each relation's scans matched on their own from the reference motion, base "
                 "frame\n");
    std::fprintf(out,
                 "  %-9s %5d %7d | %.4f +- %.4f  %6.3f +- %6.3f  (missing: no scan or no converged match)\n",
                 short_label, direct.count, direct.missing, direct.trans_mean, direct.trans_std,
                 direct.rot_mean_deg, direct.rot_std_deg);
    printContradicted(out, short_label, report, has_wheel);
  }
  if (report.has_timing) printTiming(out, short_label, report, has_wheel);
  const hglasm::CalibrationStats& calibration = report.calibration;
  std::fprintf(
      out,
      "  calibration %s: mean squared Mahalanobis distance %.2f (3 = honest covariances), median %.2f, "
      "%.1f %% within the 95 %% bound (%d relations)\n",
      short_label, calibration.mean_sq_mahalanobis, calibration.median_sq_mahalanobis,
      100.0 * calibration.fraction_within_3dof_95, calibration.count);
  std::fprintf(out, "  worst relations <= %g s (t1, span; laser m / deg | wheel m / deg):\n",
               report.short_span);
  for (const WorstRelation& worst : report.worst) {
    std::fprintf(out, "    %.3f +%.2f s  %.4f / %6.3f | ", worst.t1, worst.span, worst.laser.trans(),
                 worst.laser.rotDeg());
    if (worst.has_wheel) {
      std::fprintf(out, "%.4f / %6.3f\n", worst.wheel.trans(), worst.wheel.rotDeg());
    } else {
      std::fprintf(out, "-\n");
    }
  }
  std::fprintf(out, "  largest laser / (3 x wheel + 0.10 m) over relations <= %g s: %.3f (above 1: a leap)",
               report.short_span, report.worst_leap_ratio);
  const WorstRelation& leap = report.worst_leap;
  if (report.worst_leap_ratio > 0.0) {
    std::fprintf(out, ", %.3f +%.2f s: %.4f m | %.4f m", leap.t1, leap.span, leap.laser.trans(),
                 leap.wheel.trans());
  }
  std::fprintf(out, "\n");
}

void printWheelBlends(std::FILE* out, const std::vector<hglasm::Relation>& relations,
                      const std::vector<hglasm::StampedPose>& laser,
                      const std::vector<hglasm::StampedPose>& wheel, double short_span) {
  std::fprintf(out,
               "  blends: each step (1 - w) x the laser odometry's + w x the wheels' (w_xy, w_theta 0: the "
               "laser's)\n");
  std::fprintf(out, "    w_xy w_theta | <= %.0f s mean m / deg, median m / deg | all relations m / deg\n",
               short_span);
  const double weights[] = {0.0, 0.25, 0.5, 0.75, 1.0};
  for (double weight_xy : weights) {
    for (double weight_theta : weights) {
      const auto blended = hglasm::blendedWithWheels(laser, wheel, weight_xy, weight_theta);
      const hglasm::RelationStats short_stats = hglasm::evaluateRelations(relations, blended, short_span);
      const hglasm::RelationStats all = hglasm::evaluateRelations(relations, blended, 0.0);
      std::fprintf(out, "    %4.2f %7.2f | %.4f / %.3f, %.4f / %.3f | %.3f / %.3f\n", weight_xy, weight_theta,
                   short_stats.trans_mean, short_stats.rot_mean_deg, short_stats.trans_median,
                   short_stats.rot_median_deg, all.trans_mean, all.rot_mean_deg);
    }
  }
}

void printSummary(std::FILE* out, const std::string& preset, const EvaluationRun& run,
                  const RelationsReport& report) {
  const hglasm::Spread total = hglasm::spreadOf(run.total_ms);
  const std::size_t scans = run.processed;
  const RelationsReport& r = report;
  const hglasm::LearnedModels learned =
      run.updates.empty() ? hglasm::LearnedModels() : run.updates.back().diagnostics.learned;
  std::fprintf(
      out,
      "SUMMARY preset=%s scans=%zu fallbacks=%d fallback_pct=%.3f cpu_median_ms=%.3f cpu_p99_ms=%.3f "
      "cpu_max_ms=%.3f all_t=%.4f all_r=%.3f short_t=%.4f short_r=%.3f wheel_all_t=%.4f "
      "wheel_all_r=%.3f wheel_short_t=%.4f wheel_short_r=%.3f laser_frame_short_t=%.4f "
      "laser_frame_short_r=%.3f calibration=%.3f worst_leap=%.3f time_offset=%.3f resets=%d keyframes=%d "
      "short_t_median=%.4f short_r_median=%.3f wheel_short_t_median=%.4f wheel_short_r_median=%.3f "
      "short_scale=%.4f short_scale_error=%.4f wheel_short_scale=%.4f all_scale=%.4f wheel_all_scale=%.4f "
      "timing_ms=%.1f wheel_timing_ms=%.1f turn_scale_pct=%.2f wheel_turn_scale_pct=%.2f "
      "laser_offset_x=%.4f laser_offset_y=%.4f\n",
      preset.c_str(), scans, run.fallbacks, scans ? 100.0 * run.fallbacks / scans : 0.0, total.median,
      total.p99, total.max, r.laser_all.trans_mean, r.laser_all.rot_mean_deg, r.laser_short.trans_mean,
      r.laser_short.rot_mean_deg, r.wheel_all.trans_mean, r.wheel_all.rot_mean_deg, r.wheel_short.trans_mean,
      r.wheel_short.rot_mean_deg, r.laser_frame_short.trans_mean, r.laser_frame_short.rot_mean_deg,
      r.calibration.mean_sq_mahalanobis, r.worst_leap_ratio, run.time_offset, run.resets, run.keyframes,
      r.laser_short.trans_median, r.laser_short.rot_median_deg, r.wheel_short.trans_median,
      r.wheel_short.rot_median_deg, r.laser_short.along_track_scale, r.laser_short.along_track_scale_error,
      r.wheel_short.along_track_scale, r.laser_all.along_track_scale, r.wheel_all.along_track_scale,
      1e3 * r.laser_timing.offset, 1e3 * r.wheel_timing.offset, 1e2 * r.laser_timing.turn_scale,
      1e2 * r.wheel_timing.turn_scale, learned.laser_offset.x(), learned.laser_offset.y());
}

}  // namespace hglasm_odometry
