// evaluate: runs the nodelet's odometry pipeline (hglasm::OdometryPipeline, same options and YAML)
// over a bag as fast as the CPU allows, without a ROS master, and scores it on the Kümmerle et al.
// relations benchmark next to the bag's raw wheel odometry.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/evaluation/map_plot.h"
#include "hglasm_odometry/evaluation/relations.h"
#include "hglasm_odometry/ros/parameters.h"
#include "hglasm_odometry/tools/argument_parser.h"
#include "hglasm_odometry/tools/bag_reader.h"
#include "hglasm_odometry/tools/bag_replay.h"
#include "hglasm_odometry/tools/yaml_parameters.h"

#include <ros/package.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace {

const char kUsage[] =
    "usage: evaluate --bag B [options]\n"
    "  --bag B                 bag with sensor_msgs/LaserScan (+ nav_msgs/Odometry, /tf_static)\n"
    "  --scan-topic T          default /scan\n"
    "  --odom-topic T          default /odom\n"
    "  --config Y              default <package>/config/laser_odometry.yaml (the nodelet's parameters)\n"
    "  --presets Y             default presets.yaml next to --config (loaded under ~presets)\n"
    "  --preset P              small | medium | large or a preset of --presets (default: the YAML's)\n"
    "  --relations R           Kümmerle et al. relations file: print the benchmark metric\n"
    "  --out F                 write the trajectory, 'stamp x y theta' per scan (base frame), then the\n"
    "                          increment covariance since the previous scan (xx xy xt yy yt tt)\n"
    "  --trace F               write one line per scan: what the tracker decided and why\n"
    "  --plot F.png            plot laser and wheel odometry trajectories (gnuplot)\n"
    "  --map F.png             draw every scan at the laser odometry's poses beside the same scans at the\n"
    "                          wheel odometry's (gnuplot; metre grid, equal axis scale)\n"
    "  --no-odom               do not feed wheel odometry to the tracker (constant-velocity prior)\n"
    "  --min-scan-interval S   skip scans stamped less than S s after the last processed one\n"
    "  --laser-mount X,Y,YAW   base -> laser (m, m, rad) instead of the bag's tf\n"
    "  --max-scans N           process only the first N scans\n"
    "  --odom-stamp-shift S    move every wheel-odometry message S s later (stamp and arrival): wheels that\n"
    "                          lag the scans by S s, for the time-offset estimation (the wheel baseline\n"
    "                          is read S s later too, so it stays the bag's)\n"
    "  --angle-increment A     override the scans' angle increment (radians)\n"
    "  --angle-min A           override the scans' first beam angle (radians)\n"
    "  --max-span S            short-relation span for the second metric row (default 10 s)\n"
    "  --direct-pairs          also match each relation's own scan pair directly (MbICP started from the\n"
    "                          reference motion): how closely any one-shot match of the very scans the\n"
    "                          reference aligned can agree with it, the floor of the relations metric\n"
    "  --quiet                 no per-warning output\n";

struct Arguments {
  std::string bag;
  std::string scan_topic = "/scan";
  std::string odom_topic = "/odom";
  std::string config;  ///< empty until given or resolved (defaultConfig)
  bool config_given = false;
  std::string presets;
  bool presets_given = false;
  std::string preset;
  std::string relations;
  std::string out;
  std::string trace;
  std::string plot;
  std::string map;
  bool use_odometry = true;
  double min_scan_interval = 0.0;
  bool override_mount = false;
  hglasm::Pose2D laser_mount;
  std::size_t max_scans = 0;
  double odom_stamp_shift = 0.0;
  bool override_increment = false;
  double angle_increment = 0.0;
  bool override_angle_min = false;
  double angle_min = 0.0;
  double short_span = 10.0;
  bool direct_pairs = false;
  bool quiet = false;
};

/// X,Y,YAW into a pose (metres, metres, radians).
bool parseLaserMount(const std::string& text, hglasm::Pose2D* mount, std::string* error) {
  double x = 0.0, y = 0.0, yaw = 0.0;
  char trailing = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &x, &y, &yaw, &trailing) != 3 ||
      !hglasm::Pose2D(x, y, yaw).isFinite()) {
    *error = "expects X,Y,YAW, got '" + text + "'";
    return false;
  }
  *mount = hglasm::Pose2D(x, y, yaw);
  return true;
}

/// kOk with *args filled, or what the tool should exit with.
hglasm_odometry::ArgumentParser::Result parseArguments(int argc, char** argv, Arguments* args) {
  using Result = hglasm_odometry::ArgumentParser::Result;
  hglasm_odometry::ArgumentParser parser("evaluate", kUsage);
  parser.addOption("--bag", &args->bag);
  parser.addOption("--scan-topic", &args->scan_topic);
  parser.addOption("--odom-topic", &args->odom_topic);
  parser.addOption("--config", &args->config, &args->config_given);
  parser.addOption("--presets", &args->presets, &args->presets_given);
  parser.addOption("--preset", &args->preset);
  parser.addOption("--relations", &args->relations);
  parser.addOption("--out", &args->out);
  parser.addOption("--trace", &args->trace);
  parser.addOption("--plot", &args->plot);
  parser.addOption("--map", &args->map);
  parser.addFlag("--no-odom", &args->use_odometry, false);
  parser.addFlag("--quiet", &args->quiet);
  parser.addFlag("--direct-pairs", &args->direct_pairs);
  parser.addOption("--max-scans", &args->max_scans);
  parser.addOption("--odom-stamp-shift", &args->odom_stamp_shift);
  parser.addOption("--angle-increment", &args->angle_increment, &args->override_increment);
  parser.addOption("--angle-min", &args->angle_min, &args->override_angle_min);
  parser.addOption("--laser-mount", [args](const std::string& text, std::string* error) {
    args->override_mount = parseLaserMount(text, &args->laser_mount, error);
    return args->override_mount;
  });
  parser.addOption("--min-scan-interval", &args->min_scan_interval);
  parser.addOption("--max-span", &args->short_span);
  const Result result = parser.parse(argc, argv);
  if (result != Result::kOk) return result;
  if (args->bag.empty()) {
    parser.fail("--bag is required");
    return Result::kError;
  }
  return Result::kOk;
}

/// The installed (or devel-space) package's config/laser_odometry.yaml, found as roslaunch finds
/// $(find hglasm_odometry): through ROS_PACKAGE_PATH, so no source path is compiled in.
bool defaultConfig(std::string* path, std::string* error) {
  const std::string package = ros::package::getPath("hglasm_odometry");
  if (package.empty()) {
    const char* search_path = std::getenv("ROS_PACKAGE_PATH");
    *error =
        "cannot find the package hglasm_odometry for its config/laser_odometry.yaml (ROS_PACKAGE_PATH: " +
        std::string(search_path ? search_path : "not set") +
        "): source the workspace's setup.bash, or give --config";
    return false;
  }
  *path = package + "/config/laser_odometry.yaml";
  return true;
}

/// presets.yaml in the directory of `config`.
std::string presetsNextTo(const std::string& config) {
  const auto slash = config.find_last_of('/');
  return (slash == std::string::npos ? std::string() : config.substr(0, slash + 1)) + "presets.yaml";
}

/// The nodelet's private namespace as the launch files build it: presets.yaml under ~presets,
/// laser_odometry.yaml at the top, then ~preset from the command line; then the nodelet's loader.
bool loadNodeletOptions(const Arguments& args, hglasm_odometry::LaserOdometryOptions* options,
                        std::vector<std::string>* warnings, std::string* error) {
  // Files named on the command line must exist; absent default files mean built-in defaults.
  const auto exists = [](const std::string& path) { return std::ifstream(path).good(); };
  XmlRpc::XmlRpcValue root, presets;
  if (args.config_given || exists(args.config)) {
    if (!hglasm_odometry::loadYamlParameters(args.config, &root, error)) return false;
  } else {
    std::printf("config        %s not found: built-in defaults\n", args.config.c_str());
  }
  if (args.presets_given || exists(args.presets)) {
    if (!hglasm_odometry::loadYamlParameters(args.presets, &presets, error)) return false;
    // Accept a presets file written either as {small: ..} or as {presets: {small: ..}}.
    if (presets.size() == 1 && presets.hasMember("presets")) {
      presets = XmlRpc::XmlRpcValue(presets["presets"]);
    }
    root["presets"] = presets;
  }
  if (!args.preset.empty()) root["preset"] = args.preset;
  return hglasm_odometry::loadOptions(root, options, error, warnings);
}

double cpuMs() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return now.tv_sec * 1e3 + now.tv_nsec * 1e-6;
}

/// Median, 99th percentile and maximum of a sample (nearest-rank percentiles).
struct Spread {
  std::size_t count = 0;
  double median = 0.0, p99 = 0.0, max = 0.0, mean = 0.0;
};

Spread spreadOf(std::vector<double> values) {
  Spread spread;
  spread.count = values.size();
  if (values.empty()) return spread;
  std::sort(values.begin(), values.end());
  const auto rank = [&](double fraction) {
    const std::size_t index = static_cast<std::size_t>(std::ceil(fraction * values.size()));
    return values[std::min(values.size() - 1, index == 0 ? 0 : index - 1)];
  };
  spread.median = values.size() % 2 ? values[values.size() / 2]
                                    : 0.5 * (values[values.size() / 2 - 1] + values[values.size() / 2]);
  spread.p99 = rank(0.99);
  spread.max = values.back();
  double sum = 0.0;
  for (double value : values) sum += value;
  spread.mean = sum / values.size();
  return spread;
}

/// Wheel odometry interpolated at `stamp` (false outside the sampled span).
bool wheelPoseAt(const std::vector<hglasm_odometry::BagOdometry>& odometry, double stamp,
                 hglasm::Pose2D* pose) {
  if (odometry.empty() || stamp < odometry.front().stamp || stamp > odometry.back().stamp) return false;
  const auto after = std::lower_bound(
      odometry.begin(), odometry.end(), stamp,
      [](const hglasm_odometry::BagOdometry& sample, double value) { return sample.stamp < value; });
  if (after == odometry.begin() || after->stamp == stamp) {
    *pose = after->pose;
    return true;
  }
  const auto before = std::prev(after);
  const double span = after->stamp - before->stamp;
  *pose = span > 0.0 ? hglasm::interpolate(before->pose, after->pose, (stamp - before->stamp) / span)
                     : after->pose;
  return true;
}

/// 'stamp x y theta' per pose; with `updates` (one per pose) also the increment covariance since the
/// previous pose, 'xx xy xtheta yy ytheta thetatheta', in that pose's frame.
bool writeTrajectory(const std::string& path, const std::vector<hglasm::StampedPose>& trajectory,
                     const std::vector<hglasm::TrackerUpdate>* updates = nullptr) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return false;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const auto& pose = trajectory[i];
    std::fprintf(file, "%.6f %.6f %.6f %.6f", pose.stamp, pose.pose.x, pose.pose.y, pose.pose.theta);
    if (updates && i < updates->size()) {
      const Eigen::Matrix3d& c = (*updates)[i].increment_covariance;
      std::fprintf(file, " %.6g %.6g %.6g %.6g %.6g %.6g", c(0, 0), c(0, 1), c(0, 2), c(1, 1), c(1, 2),
                   c(2, 2));
    }
    std::fprintf(file, "\n");
  }
  return std::fclose(file) == 0;
}

/// One line per scan: the tracker's decisions (see the header line).
bool writeTrace(const std::string& path, const std::vector<hglasm::TrackerUpdate>& updates) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return false;
  std::fprintf(file,
               "# stamp x y theta prediction matched fallback doubted leap rejected keyframe map_keyframes "
               "box_x box_y box_theta population mahalanobis fitness status mbicp_iterations noise_xy "
               "noise_theta guess_x guess_y guess_theta leap_probability vx vy wz time_offset\n");
  for (const auto& u : updates) {
    std::fprintf(file,
                 "%.6f %.4f %.4f %.5f %s %d %d %d %d %d %d %d %.3f %.3f %.3f %d %.2f %.3f %s %d %.3g %.3g "
                 "%.4f %.4f %.5f %.3g %.4f %.4f %.4f %.3f\n",
                 u.stamp, u.pose.x, u.pose.y, u.pose.theta, hglasm::toString(u.prediction), u.matched,
                 u.fallback, u.prediction_doubted, u.leap, u.jump_rejected, u.new_keyframe, u.map_keyframes,
                 u.search.box.half_x, u.search.box.half_y, u.search.box.half_theta, u.search.population,
                 u.prior_mahalanobis, u.fitness_ratio, hglasm::toString(u.match.status), u.match.iterations,
                 u.noise_scale.xy, u.noise_scale.theta, u.guess.x, u.guess.y, u.guess.theta,
                 u.leap_probability, u.velocity.x(), u.velocity.y(), u.velocity.z(), u.odometry_time_offset);
  }
  return std::fclose(file) == 0;
}

/// Plots both trajectories with equal axes; the wheel one is moved so that both start at the same pose.
bool plotTrajectories(const std::string& png, const std::string& title,
                      const std::vector<hglasm::StampedPose>& laser,
                      const std::vector<hglasm::StampedPose>& wheel) {
  if (laser.empty() && wheel.empty()) return false;
  const std::string laser_data = png + ".laser.txt";
  const std::string wheel_data = png + ".wheel.txt";
  std::vector<hglasm::StampedPose> aligned_wheel = wheel;
  if (!laser.empty() && !wheel.empty()) {
    const hglasm::Pose2D align = laser.front().pose * wheel.front().pose.inverse();
    for (auto& pose : aligned_wheel) pose.pose = align * pose.pose;
  }
  if (!writeTrajectory(laser_data, laser) || !writeTrajectory(wheel_data, aligned_wheel)) return false;
  const std::string script = png + ".gnuplot";
  {
    std::ofstream out(script);
    out << "set terminal pngcairo size 1200,1000 font ',10'\n"
        << "set output '" << png << "'\n"
        << "set title \"" << title << "\" noenhanced\n"
        << "set size ratio -1\nset grid\nset key top left box opaque Left\n"
        << "set xlabel 'x (m)'\nset ylabel 'y (m)'\n"
        << "plot ";
    const char* separator = "";
    if (!aligned_wheel.empty()) {
      out << "'" << wheel_data << "' using 2:3 with lines lw 1 lc rgb '#d62728' title 'wheel odometry'";
      separator = ", ";
    }
    if (!laser.empty()) {
      out << separator << "'" << laser_data
          << "' using 2:3 with lines lw 1 lc rgb '#1f77b4' title 'laser odometry'"
          << ", '" << laser_data
          << "' every ::0::0 using 2:3 with points pt 7 ps 1.5 lc rgb 'black' title 'start'";
    }
    out << "\n";
  }
  const int status = std::system(("gnuplot '" + script + "'").c_str());
  std::remove(script.c_str());
  std::remove(laser_data.c_str());
  std::remove(wheel_data.c_str());
  return status == 0;
}

void printStatsRows(const char* label, const hglasm::RelationStats& laser, const hglasm::RelationStats& wheel,
                    bool has_wheel) {
  std::printf("  %-9s %5d %7d | %.4f +- %.4f  %6.3f +- %6.3f", label, laser.count, laser.missing,
              laser.trans_mean, laser.trans_std, laser.rot_mean_deg, laser.rot_std_deg);
  if (has_wheel) {
    std::printf(" | %.4f +- %.4f  %6.3f +- %6.3f", wheel.trans_mean, wheel.trans_std, wheel.rot_mean_deg,
                wheel.rot_std_deg);
  }
  std::printf("\n  %-9s %13s | median %.4f m  %6.3f deg    ", "", "", laser.trans_median,
              laser.rot_median_deg);
  if (has_wheel) std::printf(" | median %.4f m  %6.3f deg", wheel.trans_median, wheel.rot_median_deg);
  std::printf("\n  %-9s %13s | sq %.6f m2  %9.4f deg2", "", "", laser.trans_sq_mean, laser.rot_sq_mean_deg);
  if (has_wheel) std::printf(" | sq %.6f m2  %9.4f deg2", wheel.trans_sq_mean, wheel.rot_sq_mean_deg);
  std::printf("\n");
}

/// What one pass of the tracker over the bag produced.
struct Run {
  std::vector<hglasm::StampedPose> trajectory;  ///< published base poses, by stamp
  std::size_t processed = 0, skipped = 0, stale = 0;
  int matched = 0, fallbacks = 0, keyframes = 0, resets = 0, conversion_errors = 0, warnings = 0;
  int deskewed = 0, reanchored = 0;
  hglasm_odometry::ReplayCounts replay;
  hglasm::InputCounts inputs;
  double time_offset = 0.0;  ///< the wheels' time offset in use at the end
  std::string beam_times;    ///< where the first scan's beam times came from
  std::map<std::string, int> statuses, predictions;
  std::vector<double> total_ms, convert_ms, prealign_ms, refine_ms, table_ms;
  std::vector<hglasm::TrackerUpdate> updates;  ///< every published scan's update, in order
};

/// Where the beam times of a scan came from, for the report.
std::string beamTimesOf(const hglasm::RangeScan& ranges, const hglasm::Scan& scan) {
  if (scan.time_increment == 0.0) return "not known (time_increment and scan/sweep_time are 0)";
  char text[96];
  std::snprintf(text, sizeof text, "%.3g s per beam (%s)", scan.time_increment,
                ranges.time_increment != 0.0 ? "the bag's time_increment" : "scan/sweep_time");
  return text;
}

/// A bag scan's ranges with the command line's beam-angle overrides.
hglasm::RangeScan rangesOf(const Arguments& args, const hglasm_odometry::BagScan& bag_scan) {
  hglasm::RangeScan ranges = bag_scan.ranges;
  if (args.override_increment) ranges.angle_increment = args.angle_increment;
  if (args.override_angle_min) ranges.angle_min = args.angle_min;
  return ranges;
}

/// Runs the nodelet's pipeline over the bag as the nodelet receives it (hglasm_odometry::replayBag): the
/// bag's laser mount, scans and wheel odometry in the bag's order, each scan waiting for its inputs as the
/// nodelet's worker does at a 1x playback.
Run runTracker(const Arguments& args, const hglasm_odometry::LaserOdometryOptions& nodelet_options,
               const hglasm::TrackerOptions& options, const hglasm_odometry::BagData& data) {
  Run run;
  hglasm::OdometryPipeline pipeline(options, nodelet_options.odometry_wait > 0.0);
  hglasm_odometry::setLaserMount(data, &pipeline);
  hglasm_odometry::BagData bag = data;
  for (auto& bag_scan : bag.scans) bag_scan.ranges = rangesOf(args, bag_scan);
  hglasm_odometry::ReplayOptions replay;
  replay.odometry_wait = nodelet_options.odometry_wait;
  replay.queue_size = static_cast<std::size_t>(nodelet_options.queue_size);
  double last_processed_stamp = -std::numeric_limits<double>::infinity();
  const auto record = [&](const hglasm_odometry::ReplayedScan& replayed) {
    const hglasm::PipelineUpdate& result = replayed.update;
    const hglasm::TrackerUpdate& update = result.tracker;
    const double stamp = replayed.scan->stamp;
    ++run.processed;
    run.stale += update.stale;
    run.total_ms.push_back(replayed.cpu_ms);
    run.convert_ms.push_back(result.conversion_cpu_ms);
    if (result.scan_error != hglasm::ScanError::kNone) ++run.conversion_errors;
    if (update.matched) {
      ++run.matched;
      run.prealign_ms.push_back(update.match.prealign_ms);
      run.refine_ms.push_back(update.match.refine_ms);
      ++run.statuses[hglasm::toString(update.match.status)];
    }
    if (update.new_keyframe) run.table_ms.push_back(update.table_build_ms);
    if (!update.stale) ++run.predictions[hglasm::toString(update.prediction)];
    run.fallbacks += update.fallback;
    run.deskewed += update.deskewed;
    run.reanchored += update.reanchored;
    if (run.beam_times.empty()) run.beam_times = beamTimesOf(replayed.scan->ranges, result.scan);
    run.keyframes += update.new_keyframe;
    run.resets += update.reset && run.processed > 1;  // the first scan starts, it does not reset
    if (!update.warning.empty() && ++run.warnings <= 20 && !args.quiet) {
      std::printf("  warning at %.6f: %s\n", stamp, update.warning.c_str());
    }
    if (update.published) {
      run.trajectory.push_back({stamp, update.pose});
      run.updates.push_back(update);
    }
    last_processed_stamp = stamp;
  };
  // --min-scan-interval thins the scans before they reach the nodelet (as a throttled topic would).
  if (args.min_scan_interval > 0.0) {
    std::vector<hglasm_odometry::BagArrival> kept;
    double last_kept = -std::numeric_limits<double>::infinity();
    for (const auto& arrival : bag.arrivals) {
      if (arrival.scan) {
        const double stamp = bag.scans[arrival.index].stamp;
        if (stamp - last_kept < args.min_scan_interval) {
          ++run.skipped;
          continue;
        }
        last_kept = stamp;
      }
      kept.push_back(arrival);
    }
    bag.arrivals = kept;
  }
  run.replay = hglasm_odometry::replayBag(bag, &pipeline, replay, record);
  run.inputs = pipeline.inputCounts();
  run.time_offset = pipeline.odometryTimeOffset();
  return run;
}

void printRun(const Run& run, double data_seconds) {
  const std::size_t scans = run.processed;
  if (run.skipped) std::printf("\nskipped       %zu scans (--min-scan-interval)", run.skipped);
  std::printf(
      "\nscans         %zu processed, %d matched, %d keyframes, %d resets after the start, %zu published\n",
      scans, run.matched, run.keyframes, run.resets, run.trajectory.size());
  std::printf(
      "time policy   %zu stale scans and %llu stale odometry samples dropped, %llu clock jumps back; "
      "%zu scans dropped by the queue, %zu waits for inputs timed out (bag order, 1x playback)\n",
      run.stale, static_cast<unsigned long long>(run.inputs.stale_odometry),
      static_cast<unsigned long long>(run.inputs.jumps_back), run.replay.queue_drops,
      run.replay.wait_timeouts);
  std::printf("local map     re-anchored %d times (a scan that did not fit it)\n", run.reanchored);
  std::printf("odometry lag  time offset %.3f s in use at the end (odometry/time_offset)\n", run.time_offset);
  std::printf("fallbacks     %d (%.2f %% of scans), conversion errors %d, warnings %d\n", run.fallbacks,
              scans ? 100.0 * run.fallbacks / scans : 0.0, run.conversion_errors, run.warnings);
  std::printf("de-skewed     %d scans; beam times %s\n", run.deskewed, run.beam_times.c_str());
  std::printf("match status ");
  for (const auto& entry : run.statuses) std::printf(" %s %d", entry.first.c_str(), entry.second);
  std::printf("\nprediction   ");
  for (const auto& entry : run.predictions) std::printf(" %s %d", entry.first.c_str(), entry.second);
  int rejected = 0, doubted = 0, leaps = 0, small_searches = 0;
  double map_keyframes = 0.0;
  for (const auto& update : run.updates) {
    rejected += update.jump_rejected;
    doubted += update.prediction_doubted;
    leaps += update.leap;
    if (update.matched) {
      small_searches +=
          update.search.population <= hglasm::presetOptions(hglasm::Preset::kSmall).genetic.population;
      map_keyframes += update.map_keyframes;
    }
  }
  const hglasm::MotionNoiseScale noise =
      run.updates.empty() ? hglasm::MotionNoiseScale() : run.updates.back().noise_scale;
  std::printf(
      "\nfusion        prediction doubted %d times: %d leaps taken, %d rejected; %d of %d searches "
      "small-sized, %.1f keyframes per map; wheel noise scale learned: xy %.3g, theta %.3g",
      doubted, leaps, rejected, small_searches, run.matched, run.matched ? map_keyframes / run.matched : 0.0,
      noise.xy, noise.theta);

  std::printf("\n\nms per scan                     scans   median      p99      max  mean/scan\n");
  const auto row = [scans](const char* label, const Spread& spread) {
    std::printf("  %-29s %6zu %8.3f %8.3f %8.3f %8.3f\n", label, spread.count, spread.median, spread.p99,
                spread.max, scans ? spread.mean * spread.count / scans : 0.0);
  };
  row("scan conversion (CPU)", spreadOf(run.convert_ms));
  row("table build, keyframes (wall)", spreadOf(run.table_ms));
  row("pre-align GA (wall)", spreadOf(run.prealign_ms));
  row("refine MbICP (wall)", spreadOf(run.refine_ms));
  row("total per scan (CPU)", spreadOf(run.total_ms));
  const double cpu_seconds = spreadOf(run.total_ms).mean * scans * 1e-3;
  std::printf("  total = conversion + OdometryTracker::processScan (incl. table builds), one thread\n");
  std::printf("  total CPU %.2f s for %.1f s of data: %.0fx real time\n", cpu_seconds, data_seconds,
              cpu_seconds > 0.0 ? data_seconds / cpu_seconds : 0.0);
}

/// The trajectory of the laser instead of the base: the reference relations come from aligning scans, so
/// they may describe the laser's motion (for a laser at the base origin the two are the same).
std::vector<hglasm::StampedPose> inLaserFrame(const std::vector<hglasm::StampedPose>& trajectory,
                                              const hglasm::Pose2D& base_to_laser) {
  std::vector<hglasm::StampedPose> laser;
  laser.reserve(trajectory.size());
  for (const auto& stamped : trajectory) laser.push_back({stamped.stamp, stamped.pose * base_to_laser});
  return laser;
}

/// Each relation's scan pair matched on its own with MbICP, started from the reference motion (in the
/// laser frame): base-frame motions per relation, valid where both stamps have a scan and MbICP
/// converged. Not odometry: the reference is the start, so this shows how far the matcher's optimum of
/// those very scans lies from the reference.
void directPairs(const Arguments& args, const hglasm::TrackerOptions& options,
                 const hglasm_odometry::BagData& data, const std::vector<hglasm::Relation>& relations,
                 double max_span, std::vector<hglasm::Pose2D>* motions, std::vector<bool>* valid) {
  // The pipeline's conversion for this bag (mirrored for an upside-down laser).
  hglasm::OdometryPipeline pipeline(options);
  hglasm_odometry::setLaserMount(data, &pipeline);
  const hglasm::ScanConversionOptions conversion = pipeline.conversion();
  const hglasm::Pose2D mount = data.has_laser_mount ? data.base_to_laser : hglasm::Pose2D();
  const auto scan_at = [&](double stamp) -> const hglasm_odometry::BagScan* {
    const auto it = std::lower_bound(
        data.scans.begin(), data.scans.end(), stamp - 1e-3,
        [](const hglasm_odometry::BagScan& scan, double value) { return scan.stamp < value; });
    return it != data.scans.end() && std::abs(it->stamp - stamp) <= 1e-3 ? &*it : nullptr;
  };
  const auto convert = [&](const hglasm_odometry::BagScan& bag_scan) {
    return hglasm::scanFromRanges(rangesOf(args, bag_scan), conversion);
  };
  hglasm::ScanMatcher matcher(options.matcher);
  motions->assign(relations.size(), hglasm::Pose2D());
  valid->assign(relations.size(), false);
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const hglasm::Relation& relation = relations[k];
    if (max_span > 0.0 && std::abs(relation.t2 - relation.t1) > max_span) continue;
    const hglasm_odometry::BagScan* first = scan_at(relation.t1);
    const hglasm_odometry::BagScan* second = scan_at(relation.t2);
    if (!first || !second) continue;
    matcher.setReference(convert(*first));
    const hglasm::Pose2D start = mount.inverse() * relation.motion * mount;
    const hglasm::MatchResult result = matcher.refine(convert(*second), start);
    if (result.status != hglasm::MatchStatus::kOk) continue;
    (*motions)[k] = mount * result.pose * mount.inverse();
    (*valid)[k] = true;
  }
}

/// Prints the short relations with the largest translational errors beside the wheels' errors on them,
/// and returns the largest ratio laser error / (3 x wheel error + 0.10 m) over them: above 1 is a leap the
/// wheels did not make.
double printWorstRelations(const std::vector<hglasm::Relation>& relations,
                           const std::vector<hglasm::StampedPose>& trajectory,
                           const std::vector<hglasm::StampedPose>& wheel_trajectory, double max_span) {
  std::vector<hglasm::RelationError> laser = hglasm::relationErrors(relations, trajectory, max_span);
  const std::vector<hglasm::RelationError> wheel =
      hglasm::relationErrors(relations, wheel_trajectory, max_span);
  std::map<std::size_t, hglasm::RelationError> wheel_by_index;
  for (const auto& error : wheel) wheel_by_index[error.index] = error;
  double worst_ratio = 0.0;
  for (const auto& error : laser) {
    const auto it = wheel_by_index.find(error.index);
    if (it == wheel_by_index.end()) continue;
    worst_ratio = std::max(worst_ratio, error.trans / (3.0 * it->second.trans + 0.10));
  }
  std::sort(laser.begin(), laser.end(), [](const auto& a, const auto& b) { return a.trans > b.trans; });
  std::printf("  worst relations <= %g s (t1, span; laser m / deg | wheel m / deg):\n", max_span);
  for (std::size_t k = 0; k < std::min<std::size_t>(5, laser.size()); ++k) {
    const hglasm::Relation& relation = relations[laser[k].index];
    const auto it = wheel_by_index.find(laser[k].index);
    std::printf("    %.3f +%.2f s  %.4f / %6.3f | ", relation.t1, relation.t2 - relation.t1, laser[k].trans,
                laser[k].rot_deg);
    if (it != wheel_by_index.end()) {
      std::printf("%.4f / %6.3f\n", it->second.trans, it->second.rot_deg);
    } else {
      std::printf("-\n");
    }
  }
  std::printf("  largest laser / (3 x wheel + 0.10 m) over relations <= %g s: %.3f (above 1: a leap)\n",
              max_span, worst_ratio);
  return worst_ratio;
}

void printRelations(const Arguments& args, const std::string& preset_name, const Run& run,
                    const std::vector<hglasm::Relation>& relations,
                    const std::vector<hglasm::StampedPose>& wheel_trajectory,
                    const hglasm::TrackerOptions& options, const hglasm_odometry::BagData& data) {
  const bool has_wheel = !wheel_trajectory.empty();
  std::printf("\nrelations     %s: %zu (Kümmerle et al. 2009; mean +- std, population)\n",
              args.relations.c_str(), relations.size());
  const auto laser_all = hglasm::evaluateRelations(relations, run.trajectory, 0.0);
  const auto wheel_all = hglasm::evaluateRelations(relations, wheel_trajectory, 0.0);
  const auto laser_short = hglasm::evaluateRelations(relations, run.trajectory, args.short_span);
  const auto wheel_short = hglasm::evaluateRelations(relations, wheel_trajectory, args.short_span);
  char short_label[32];
  std::snprintf(short_label, sizeof(short_label), "<= %g s", args.short_span);
  std::printf("  %-9s %5s %7s | %-33s", "relations", "n", "missing", "laser odometry: m, deg");
  if (has_wheel) std::printf(" | %s", "wheel odometry: m, deg");
  std::printf("\n  base frame ('%s', the trajectory's)\n", data.base_frame.c_str());
  printStatsRows("all", laser_all, wheel_all, has_wheel);
  printStatsRows(short_label, laser_short, wheel_short, has_wheel);

  const bool laser_offset = data.has_laser_mount && !(data.base_to_laser.translationNorm() < 1e-9 &&
                                                      std::abs(data.base_to_laser.theta) < 1e-9);
  hglasm::RelationStats laser_frame_short = laser_short;
  if (laser_offset) {
    const auto laser_trajectory = inLaserFrame(run.trajectory, data.base_to_laser);
    const auto wheel_laser = inLaserFrame(wheel_trajectory, data.base_to_laser);
    laser_frame_short = hglasm::evaluateRelations(relations, laser_trajectory, args.short_span);
    std::printf(
        "  laser frame (the same trajectories moved to the laser, if the reference describes its motion)\n");
    printStatsRows("all", hglasm::evaluateRelations(relations, laser_trajectory, 0.0),
                   hglasm::evaluateRelations(relations, wheel_laser, 0.0), has_wheel);
    printStatsRows(short_label, laser_frame_short,
                   hglasm::evaluateRelations(relations, wheel_laser, args.short_span), has_wheel);
  }
  if (args.direct_pairs) {
    std::vector<hglasm::Pose2D> motions;
    std::vector<bool> valid;
    directPairs(args, options, data, relations, args.short_span, &motions, &valid);
    const auto direct = hglasm::evaluateRelativeMotions(relations, motions, valid, args.short_span);
    std::printf(
        "  direct pairs: each relation's scans matched on their own from the reference motion, base frame\n");
    std::printf("  %-9s %5d %7d | %.4f +- %.4f  %6.3f +- %6.3f  (missing: no scan or no converged match)\n",
                short_label, direct.count, direct.missing, direct.trans_mean, direct.trans_std,
                direct.rot_mean_deg, direct.rot_std_deg);
  }
  std::vector<Eigen::Matrix3d> increments;
  for (const auto& update : run.updates) increments.push_back(update.increment_covariance);
  const hglasm::CalibrationStats calibration =
      hglasm::evaluateCalibration(relations, run.trajectory, increments, args.short_span);
  std::printf(
      "  calibration %s: mean squared Mahalanobis distance %.2f (3 = honest covariances), median %.2f, "
      "%.1f %% within the 95 %% bound (%d relations)\n",
      short_label, calibration.mean_sq_mahalanobis, calibration.median_sq_mahalanobis,
      100.0 * calibration.fraction_within_3dof_95, calibration.count);
  const double worst_leap = printWorstRelations(relations, run.trajectory, wheel_trajectory, args.short_span);
  // One machine-readable line for scripts/evaluate_all.sh.
  const Spread total = spreadOf(run.total_ms);
  const std::size_t scans = run.processed;
  std::printf(
      "SUMMARY preset=%s scans=%zu fallbacks=%d fallback_pct=%.3f cpu_median_ms=%.3f cpu_p99_ms=%.3f "
      "cpu_max_ms=%.3f all_t=%.4f all_r=%.3f short_t=%.4f short_r=%.3f wheel_all_t=%.4f "
      "wheel_all_r=%.3f wheel_short_t=%.4f wheel_short_r=%.3f laser_frame_short_t=%.4f "
      "laser_frame_short_r=%.3f calibration=%.3f worst_leap=%.3f time_offset=%.3f resets=%d keyframes=%d "
      "short_t_median=%.4f short_r_median=%.3f wheel_short_t_median=%.4f wheel_short_r_median=%.3f\n",
      preset_name.c_str(), scans, run.fallbacks, scans ? 100.0 * run.fallbacks / scans : 0.0, total.median,
      total.p99, total.max, laser_all.trans_mean, laser_all.rot_mean_deg, laser_short.trans_mean,
      laser_short.rot_mean_deg, wheel_all.trans_mean, wheel_all.rot_mean_deg, wheel_short.trans_mean,
      wheel_short.rot_mean_deg, laser_frame_short.trans_mean, laser_frame_short.rot_mean_deg,
      calibration.mean_sq_mahalanobis, worst_leap, run.time_offset, run.resets, run.keyframes,
      laser_short.trans_median, laser_short.rot_median_deg, wheel_short.trans_median,
      wheel_short.rot_median_deg);
}

/// The bag (its laser mount replaced by --laser-mount if given) and the relations, with a line on each.
bool readInputs(const Arguments& args, const std::string& base_frame, hglasm_odometry::BagData* data,
                std::vector<hglasm::Relation>* relations) {
  hglasm_odometry::BagReadOptions read_options;
  read_options.scan_topic = args.scan_topic;
  read_options.odom_topic = args.odom_topic;
  read_options.max_scans = args.max_scans;
  read_options.base_frame = base_frame;
  std::string error;
  const double read_start = cpuMs();
  if (!hglasm_odometry::readBag(args.bag, read_options, data, &error)) {
    std::cerr << "evaluate: " << error << "\n";
    return false;
  }
  if (!args.relations.empty() && !hglasm::readRelations(args.relations, relations, &error)) {
    std::cerr << "evaluate: " << error << "\n";
    return false;
  }
  std::printf("bag           %s: %zu scans, %zu odometry samples (read in %.1f s CPU)\n", args.bag.c_str(),
              data->scans.size(), data->odometry.size(), (cpuMs() - read_start) * 1e-3);
  const char* mount_source = data->has_laser_mount ? "from tf" : "not found, identity";
  if (args.override_mount) {
    data->has_laser_mount = true;
    data->base_to_laser = args.laser_mount;
    mount_source = "from --laser-mount";
  }
  std::printf("laser mount   %s: base '%s' -> laser '%s' = (%.3f, %.3f, %.3f rad)%s\n", mount_source,
              data->base_frame.c_str(), data->scans.front().frame_id.c_str(), data->base_to_laser.x,
              data->base_to_laser.y, data->base_to_laser.theta,
              data->laser_upside_down ? ", upside down (scans mirrored)" : "");
  return true;
}

/// The map picture: every scan (the pipeline's conversion, mirrored for an upside-down laser) drawn at the
/// laser poses of the laser odometry and, beside them, of the wheel odometry started at the same pose.
bool plotMap(const Arguments& args, const std::string& title, const hglasm::TrackerOptions& options,
             const hglasm_odometry::BagData& data, const Run& run,
             const std::vector<hglasm::StampedPose>& wheel_trajectory) {
  hglasm::OdometryPipeline pipeline(options);
  hglasm_odometry::setLaserMount(data, &pipeline);
  const hglasm::Pose2D mount = data.has_laser_mount ? data.base_to_laser : hglasm::Pose2D();
  std::vector<double> stamps;
  std::vector<std::vector<Eigen::Vector2d>> scans;
  for (const auto& bag_scan : data.scans) {
    stamps.push_back(bag_scan.stamp);
    scans.push_back(hglasm::scanFromRanges(rangesOf(args, bag_scan), pipeline.conversion()).points);
  }
  const std::vector<hglasm::MapView> views =
      hglasm::laserAndWheelViews(stamps, run.trajectory, wheel_trajectory, mount);
  hglasm::MapPlotOptions map_options;
  map_options.title = title + ": scans at the laser poses";
  std::string error;
  if (!hglasm::writeMapPlot(args.map, scans, views, map_options, &error)) {
    std::cerr << "evaluate: " << error << "\n";
    return false;
  }
  std::printf("map           %s\n", args.map.c_str());
  return true;
}

/// --out, --trace, --plot and --map, each if asked for.
bool writeOutputs(const Arguments& args, const std::string& preset, const Run& run,
                  const std::vector<hglasm::StampedPose>& wheel_trajectory,
                  const hglasm::TrackerOptions& options, const hglasm_odometry::BagData& data) {
  if (!args.out.empty()) {
    if (!writeTrajectory(args.out, run.trajectory, &run.updates)) {
      std::cerr << "evaluate: cannot write " << args.out << "\n";
      return false;
    }
    std::printf("trajectory    %s (%zu poses)\n", args.out.c_str(), run.trajectory.size());
  }
  if (!args.trace.empty()) {
    if (!writeTrace(args.trace, run.updates)) {
      std::cerr << "evaluate: cannot write " << args.trace << "\n";
      return false;
    }
    std::printf("trace         %s\n", args.trace.c_str());
  }
  const std::string title = args.bag.substr(args.bag.find_last_of('/') + 1) + ", preset " + preset;
  if (!args.plot.empty()) {
    if (!plotTrajectories(args.plot, title, run.trajectory, wheel_trajectory)) {
      std::cerr << "evaluate: gnuplot failed for " << args.plot << "\n";
      return false;
    }
    std::printf("plot          %s\n", args.plot.c_str());
  }
  return args.map.empty() || plotMap(args, title, options, data, run, wheel_trajectory);
}

}  // namespace

int main(int argc, char** argv) {
  Arguments args;
  const auto parsed = parseArguments(argc, argv, &args);
  if (parsed != hglasm_odometry::ArgumentParser::Result::kOk) return hglasm_odometry::exitStatus(parsed);
  std::string error;
  if (!args.config_given && !defaultConfig(&args.config, &error)) {
    std::cerr << "evaluate: " << error << "\n";
    return 2;
  }
  if (args.presets.empty()) args.presets = presetsNextTo(args.config);

  // The nodelet's options, through the nodelet's own loader.
  hglasm_odometry::LaserOdometryOptions nodelet_options;
  std::vector<std::string> config_warnings;
  if (!loadNodeletOptions(args, &nodelet_options, &config_warnings, &error)) {
    std::cerr << "evaluate: " << error << "\n";
    return 2;
  }
  for (const auto& warning : config_warnings) std::printf("config        warning: %s\n", warning.c_str());
  hglasm::TrackerOptions options = nodelet_options.tracker;
  if (!args.use_odometry) options.use_odometry = false;

  hglasm_odometry::BagData data;
  std::vector<hglasm::Relation> relations;
  if (!readInputs(args, nodelet_options.base_frame, &data, &relations)) return 1;
  if (args.odom_stamp_shift != 0.0) {
    hglasm_odometry::shiftOdometry(args.odom_stamp_shift, &data);
    std::printf("odometry      every message moved %.3f s later (--odom-stamp-shift)\n",
                args.odom_stamp_shift);
  }
  std::printf("options       %s, preset %s, wheel odometry %s\n", args.config.c_str(),
              nodelet_options.preset.c_str(),
              !options.use_odometry   ? "off"
              : data.odometry.empty() ? "on (but none in the bag)"
                                      : "on");

  const Run run = runTracker(args, nodelet_options, options, data);
  printRun(run, data.scans.back().stamp - data.scans.front().stamp);

  // Wheel odometry at the scan stamps: the baseline the laser must beat.
  std::vector<hglasm::StampedPose> wheel_trajectory;
  for (const auto& bag_scan : data.scans) {
    hglasm::Pose2D pose;
    if (wheelPoseAt(data.odometry, bag_scan.stamp + args.odom_stamp_shift, &pose)) {
      wheel_trajectory.push_back({bag_scan.stamp, pose});
    }
  }
  if (!relations.empty())
    printRelations(args, nodelet_options.preset, run, relations, wheel_trajectory, options, data);

  return writeOutputs(args, nodelet_options.preset, run, wheel_trajectory, options, data) ? 0 : 1;
}
