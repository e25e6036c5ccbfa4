// success_ratio: the papers' Success-Ratio experiment on real scans from a bag or a CARMEN log.
// The protocol lives in hglasm/core/success_ratio.h; this main parses arguments, reads the scans,
// prints progress on stderr, writes the CSVs and runs gnuplot on the generated plot scripts.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "hglasm_odometry/core/carmen_log.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/core/success_ratio.h"
#include "hglasm_odometry/ros/bag_reader.h"

namespace {

constexpr int kExitRuntimeError = 1;
constexpr int kExitBadArguments = 2;

const char kUsage[] =
    "usage: success_ratio (--bag PATH [--topic /scan] | --carmen PATH) --trials N --seed S --csv PATH\n"
    "                     [--plots DIR] [--algorithms LIST] [--presets LIST] [--cases paper|none|LIST]\n"
    "                     [--in-box] [other options]\n"
    "The papers' protocol: reference = odd beams of a random scan, new scan = its even beams moved by a\n"
    "known initial position error; success = final |dxy| < 0.10 m and |dtheta| < 0.01 rad (GA alone:\n"
    "0.30 m / 0.1 rad). One thread; deterministic for a seed (except the timings).\n"
    "  --bag PATH               bag with sensor_msgs/LaserScan messages\n"
    "  --topic T                scan topic in the bag (default /scan)\n"
    "  --carmen PATH            CARMEN text log (FLASER lines; -90..+90 deg unless overridden)\n"
    "  --trials N               trials per (algorithm, preset, case)\n"
    "  --seed S                 random seed (unsigned integer)\n"
    "  --csv PATH               result rows: algorithm,preset,rot_err_deg,trans_err_m,trials,successes,\n"
    "                           success_ratio,mean_dxy_m,mean_dth_deg,mean_ms,ceiling\n"
    "  --plots DIR              write PNGs (gnuplot): success vs rotation error per algorithm+preset,\n"
    "                           pre-alignment vs fitness evaluations per preset\n"
    "  --algorithms LIST        comma list of hglasm_g,hglasm_binary,glasm_g,glasm_binary,mbicp,pga,hpga\n"
    "                           (default all)\n"
    "  --presets LIST           comma list of small,medium,large (default all)\n"
    "  --cases C                paper (default: rotation 0..180 deg x translation 0.14,0.57,1.13,2.12 m),\n"
    "                           none, or ROT_DEG:TRANS_M,... e.g. 20:0.57,90:1.13\n"
    "  --in-box                 add per preset: errors uniform in the preset's whole search box\n"
    "  --curve-trials N         trials per point of the GA-vs-fitness-evaluations curves (default: "
    "--trials;\n"
    "                           0 = skip the curves)\n"
    "  --curve-generations LIST generation counts of the curves (default 1,2,3,4,6,8,... up to 2x preset)\n"
    "  --curve-csv PATH         curve rows (default: --csv with _evaluations.csv instead of .csv)\n"
    "  --curve-algorithms LIST  GA-alone algorithms of the curves (default glasm_g,glasm_binary,pga)\n"
    "  --time-csv PATH          time to reach 50/70/80/90/95 % from the curves (default: --csv with\n"
    "                           _time_to_reach.csv instead of .csv)\n"
    "  --no-ceiling             skip the ceiling (success at zero initial error, per algorithm and preset)\n"
    "  --interlace-seconds S    the odd beams are recorded S s after the even ones (fr079: 0.014): the\n"
    "                           truth of each trial is rotated (and moved) by the laser's motion over S,\n"
    "                           from the bag's wheel odometry at the scan (--bag only)\n"
    "  --max-scans N            read only the first N scans (default all)\n"
    "  --min-points N           skip scans with fewer valid points in their odd or even beams (default 40)\n"
    "  --angle-min A            override the first beam angle (radians)\n"
    "  --angle-increment A      override the beam spacing (radians)\n"
    "  --title TEXT             plot title prefix (default: the input file name)\n"
    "  --quiet                  no per-cell progress\n"
    "  --help\n";

struct Arguments {
  std::string bag;
  std::string topic = "/scan";
  bool topic_given = false;
  std::string carmen;
  int trials = 0;
  bool trials_given = false;
  std::uint64_t seed = 0;
  bool seed_given = false;
  std::string csv;
  std::string plots;
  std::string algorithms = "hglasm_g,hglasm_binary,glasm_g,glasm_binary,mbicp,pga,hpga";
  std::string curve_algorithms = "glasm_g,glasm_binary,pga";
  std::string time_csv;
  bool ceiling = true;
  double interlace_seconds = 0.0;
  std::string presets = "small,medium,large";
  std::string cases = "paper";
  bool in_box = false;
  int curve_trials = -1;  // -1: same as trials
  std::string curve_generations;
  std::string curve_csv;
  std::size_t max_scans = 0;
  int min_points = 40;
  bool override_angle_min = false;
  double angle_min = 0.0;
  bool override_increment = false;
  double angle_increment = 0.0;
  std::string title;
  bool quiet = false;
};

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) items.push_back(item);
  return items;
}

template <typename Integer>
bool parseInteger(const std::string& text, Integer* value) {
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, *value);
  return !text.empty() && result.ec == std::errc() && result.ptr == end;
}

bool parseFinite(const std::string& text, double* value) {
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return !text.empty() && *end == '\0' && std::isfinite(*value);
}

// Bad arguments: the message and a pointer to the usage.
bool fail(const std::string& message) {
  std::cerr << "success_ratio: " << message << "\n(--help for usage)\n";
  return false;
}

// Failures after the arguments were accepted (unreadable input, unwritable output).
bool failRuntime(const std::string& message) {
  std::cerr << "success_ratio: error: " << message << "\n";
  return false;
}

// Options whose value is kept as given.
std::string Arguments::*textOption(const std::string& flag) {
  static const std::pair<const char*, std::string Arguments::*> kTextOptions[] = {
      {"--bag", &Arguments::bag},
      {"--carmen", &Arguments::carmen},
      {"--csv", &Arguments::csv},
      {"--plots", &Arguments::plots},
      {"--algorithms", &Arguments::algorithms},
      {"--presets", &Arguments::presets},
      {"--cases", &Arguments::cases},
      {"--curve-generations", &Arguments::curve_generations},
      {"--curve-csv", &Arguments::curve_csv},
      {"--curve-algorithms", &Arguments::curve_algorithms},
      {"--time-csv", &Arguments::time_csv},
      {"--title", &Arguments::title}};
  for (const auto& [name, member] : kTextOptions) {
    if (flag == name) return member;
  }
  return nullptr;
}

bool parseArguments(int argc, char** argv, Arguments* args) {
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    std::string text;
    const auto value = [&]() {
      if (i + 1 >= argc) return false;
      text = argv[++i];
      return true;
    };
    const auto needs_value = [&]() { return fail(flag + " needs a value"); };
    if (flag == "--help" || flag == "-h") {
      std::cout << kUsage;
      std::exit(0);
    } else if (flag == "--in-box") {
      args->in_box = true;
    } else if (flag == "--quiet") {
      args->quiet = true;
    } else if (flag == "--no-ceiling") {
      args->ceiling = false;
    } else if (!value()) {
      if (flag.rfind("--", 0) != 0) return fail("unexpected argument '" + flag + "'");
      const bool known = textOption(flag) || flag == "--topic" || flag == "--trials" || flag == "--seed" ||
                         flag == "--curve-trials" || flag == "--max-scans" || flag == "--min-points" ||
                         flag == "--angle-min" || flag == "--angle-increment" ||
                         flag == "--interlace-seconds";
      return known ? needs_value() : fail("unknown option '" + flag + "'");
    } else if (std::string Arguments::*member = textOption(flag)) {
      args->*member = text;
    } else if (flag == "--topic") {
      args->topic = text;
      args->topic_given = true;
    } else if (flag == "--trials") {
      if (!parseInteger(text, &args->trials) || args->trials < 1) {
        return fail("--trials: expected a positive integer, got '" + text + "'");
      }
      args->trials_given = true;
    } else if (flag == "--seed") {
      if (!parseInteger(text, &args->seed))
        return fail("--seed: expected an unsigned integer, got '" + text + "'");
      args->seed_given = true;
    } else if (flag == "--curve-trials") {
      if (!parseInteger(text, &args->curve_trials) || args->curve_trials < 0) {
        return fail("--curve-trials: expected an integer >= 0, got '" + text + "'");
      }
    } else if (flag == "--max-scans") {
      if (!parseInteger(text, &args->max_scans))
        return fail("--max-scans: expected an integer, got '" + text + "'");
    } else if (flag == "--min-points") {
      if (!parseInteger(text, &args->min_points) || args->min_points < 3) {
        return fail("--min-points: expected an integer >= 3, got '" + text + "'");
      }
    } else if (flag == "--angle-min") {
      if (!parseFinite(text, &args->angle_min)) return fail("--angle-min: not a number: '" + text + "'");
      args->override_angle_min = true;
    } else if (flag == "--angle-increment") {
      if (!parseFinite(text, &args->angle_increment) || args->angle_increment == 0.0) {
        return fail("--angle-increment: expected a non-zero number, got '" + text + "'");
      }
      args->override_increment = true;
    } else if (flag == "--interlace-seconds") {
      if (!parseFinite(text, &args->interlace_seconds))
        return fail("--interlace-seconds: not a number: '" + text + "'");
    } else {
      return fail("unknown option '" + flag + "'");
    }
  }
  if (args->bag.empty() == args->carmen.empty())
    return fail("give exactly one of --bag PATH or --carmen PATH");
  if (args->topic_given && args->bag.empty()) return fail("--topic applies to --bag only");
  if (!args->trials_given) return fail("--trials N is required");
  if (!args->seed_given) return fail("--seed S is required");
  if (args->csv.empty()) return fail("--csv PATH is required");
  if (args->interlace_seconds != 0.0 && args->bag.empty())
    return fail("--interlace-seconds needs --bag (the turn rate comes from its wheel odometry)");
  return true;
}

bool parseAlgorithms(const std::string& flag, const std::string& list,
                     std::vector<hglasm::Algorithm>* algorithms) {
  algorithms->clear();
  for (const std::string& name : splitList(list)) {
    hglasm::Algorithm algorithm;
    if (!hglasm::parseAlgorithm(name, &algorithm)) {
      return fail(flag + ": unknown algorithm '" + name +
                  "' (hglasm_g, hglasm_binary, glasm_g, glasm_binary, mbicp, pga, hpga)");
    }
    if (std::find(algorithms->begin(), algorithms->end(), algorithm) == algorithms->end())
      algorithms->push_back(algorithm);
  }
  return true;
}

bool buildOptions(const Arguments& args, hglasm::SuccessRatioOptions* options) {
  if (!parseAlgorithms("--algorithms", args.algorithms, &options->algorithms)) return false;
  if (!parseAlgorithms("--curve-algorithms", args.curve_algorithms, &options->curve_algorithms)) return false;
  for (hglasm::Algorithm algorithm : options->curve_algorithms) {
    if (hglasm::usesMbicpStage(algorithm) || !hglasm::usesGeneticStage(algorithm))
      return fail("--curve-algorithms: the curves are of GA-alone algorithms (glasm_g, glasm_binary, pga)");
  }
  options->ceiling = args.ceiling;
  for (const std::string& name : splitList(args.presets)) {
    hglasm::Preset preset;
    if (!hglasm::parsePreset(name, &preset))
      return fail("unknown preset '" + name + "' (small, medium, large)");
    if (std::find(options->presets.begin(), options->presets.end(), preset) == options->presets.end()) {
      options->presets.push_back(preset);
    }
  }
  if (options->algorithms.empty()) return fail("--algorithms: empty list");
  if (options->presets.empty()) return fail("--presets: empty list");
  std::string error;
  if (!hglasm::parseCases(args.cases, &options->cases, &error)) return fail("--cases: " + error);
  if (options->cases.empty() && !args.in_box && args.curve_trials == 0) {
    return fail("nothing to run: --cases none without --in-box and with --curve-trials 0");
  }
  for (const std::string& item : splitList(args.curve_generations)) {
    int generations = 0;
    if (!parseInteger(item, &generations) || generations < 1) {
      return fail("--curve-generations: expected positive integers, got '" + item + "'");
    }
    options->curve_generations.push_back(generations);
  }
  options->in_box = args.in_box;
  options->trials = args.trials;
  options->seed = args.seed;
  options->min_points_per_half = args.min_points;
  options->curve_trials = args.curve_trials < 0 ? args.trials : args.curve_trials;
  return true;
}

// The base's velocity (vx, vy, omega in its own frame) at `stamp`: the wheel odometry's motion between the
// samples around it; zero when there are fewer than two samples.
Eigen::Vector3d baseVelocityAt(const std::vector<hglasm_odometry::BagOdometry>& odometry, double stamp) {
  if (odometry.size() < 2) return Eigen::Vector3d::Zero();
  const auto after =
      std::upper_bound(odometry.begin(), odometry.end(), stamp,
                       [](double t, const hglasm_odometry::BagOdometry& o) { return t < o.stamp; });
  std::size_t next = static_cast<std::size_t>(after - odometry.begin());
  next = std::clamp<std::size_t>(next, 1, odometry.size() - 1);
  const hglasm_odometry::BagOdometry& a = odometry[next - 1];
  const hglasm_odometry::BagOdometry& b = odometry[next];
  const double dt = b.stamp - a.stamp;
  if (!(dt > 0.0)) return Eigen::Vector3d::Zero();
  const hglasm::Pose2D motion = hglasm::relativePose(a.pose, b.pose);
  return Eigen::Vector3d(motion.x, motion.y, motion.theta) / dt;
}

bool readScans(const Arguments& args, std::vector<hglasm::RangeScan>* scans,
               std::vector<hglasm::Pose2D>* half_offsets) {
  std::string error;
  if (!args.carmen.empty()) {
    hglasm::CarmenLogOptions log_options;
    log_options.max_scans = args.max_scans;
    hglasm::CarmenLog log;
    if (!hglasm::readCarmenLog(args.carmen, log_options, &log, &error)) return failRuntime(error);
    std::cerr << "success_ratio: read " << log.scans.size() << " FLASER scans from " << args.carmen;
    if (log.malformed_lines > 0) {
      std::cerr << " (" << log.malformed_lines << " malformed lines skipped, first at line "
                << log.first_malformed_line << ")";
    }
    std::cerr << "\n";
    for (const hglasm::CarmenLaserReading& reading : log.scans) scans->push_back(reading.ranges);
  } else {
    hglasm_odometry::BagReadOptions bag_options;
    bag_options.scan_topic = args.topic;
    if (args.interlace_seconds == 0.0) bag_options.odom_topic.clear();  // only the scans matter here
    bag_options.max_scans = args.max_scans;
    hglasm_odometry::BagData data;
    if (!hglasm_odometry::readBag(args.bag, bag_options, &data, &error)) return failRuntime(error);
    std::cerr << "success_ratio: read " << data.scans.size() << " scans on " << args.topic << " from "
              << args.bag << "\n";
    if (args.interlace_seconds != 0.0) {
      if (data.odometry.size() < 2) return failRuntime("--interlace-seconds: the bag has no wheel odometry");
      for (const hglasm_odometry::BagScan& scan : data.scans) {
        half_offsets->push_back(hglasm::halfScanOffset(baseVelocityAt(data.odometry, scan.stamp),
                                                       data.base_to_laser, args.interlace_seconds));
      }
      std::cerr << "success_ratio: truths offset by the laser's motion over " << args.interlace_seconds
                << " s (wheel odometry, " << data.odometry.size() << " samples)\n";
    }
    for (hglasm_odometry::BagScan& scan : data.scans) scans->push_back(std::move(scan.ranges));
  }
  if (scans->empty()) return failRuntime("no scans read");
  for (hglasm::RangeScan& scan : *scans) {
    if (args.override_angle_min) scan.angle_min = args.angle_min;
    if (args.override_increment) scan.angle_increment = args.angle_increment;
  }
  return true;
}

std::string shellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// `csv` with `tail` (e.g. "_evaluations.csv") in place of its ".csv".
std::string siblingCsv(const std::string& csv, const std::string& tail) {
  const std::string suffix = ".csv";
  if (csv.size() > suffix.size() && csv.compare(csv.size() - suffix.size(), suffix.size(), suffix) == 0) {
    return csv.substr(0, csv.size() - suffix.size()) + tail;
  }
  return csv + tail;
}

bool writePlots(const hglasm::SuccessRatioReport& report, const Arguments& args) {
  std::error_code ec;
  std::filesystem::create_directories(args.plots, ec);
  if (ec) return failRuntime("cannot create plot directory '" + args.plots + "': " + ec.message());
  std::string title = args.title;
  if (title.empty())
    title = std::filesystem::path(args.bag.empty() ? args.carmen : args.bag).filename().string();
  std::vector<std::string> scripts;
  std::string error;
  if (!hglasm::writeSuccessRatioPlotScripts(report, args.plots, title, &scripts, &error))
    return failRuntime(error);
  if (scripts.empty()) {
    std::cerr << "success_ratio: nothing to plot (success plots need >= 2 rotation errors, curves need "
                 "--curve-trials > 0)\n";
    return true;
  }
  for (const std::string& script : scripts) {
    const std::string command = "gnuplot " + shellQuote(script);
    if (std::system(command.c_str()) != 0) {
      return failRuntime("gnuplot failed on " + script +
                         " (is gnuplot installed? Debian package gnuplot-nox)");
    }
    std::cerr << "success_ratio: wrote " << script.substr(0, script.size() - 3) << ".png\n";
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Arguments args;
  if (!parseArguments(argc, argv, &args)) return kExitBadArguments;
  hglasm::SuccessRatioOptions options;
  if (!buildOptions(args, &options)) return kExitBadArguments;

  // Fail on unwritable outputs now, not after a long run.
  if (!std::ofstream(args.csv, std::ios::app)) {
    failRuntime("cannot write '" + args.csv + "'");
    return kExitRuntimeError;
  }
  if (!args.plots.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(args.plots, ec);
    if (ec) {
      failRuntime("cannot create plot directory '" + args.plots + "': " + ec.message());
      return kExitRuntimeError;
    }
  }

  std::vector<hglasm::RangeScan> scans;
  if (!readScans(args, &scans, &options.half_offsets)) return kExitRuntimeError;

  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&start]() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  hglasm::SuccessRatioReport report;
  std::string error;
  const auto progress = [&](const hglasm::SuccessRatioProgress& state) {
    if (args.quiet) return;
    char prefix[64];
    std::snprintf(prefix, sizeof(prefix), "[%4zu/%-4zu %6.0fs] ", state.cells_done, state.cells_total,
                  elapsed());
    std::cerr << prefix << state.message << "\n";
  };
  std::cerr << "success_ratio: " << options.algorithms.size() << " algorithm(s) x " << options.presets.size()
            << " preset(s) x " << options.cases.size() << " case(s)" << (options.in_box ? " + in-box" : "")
            << ", " << options.trials << " trials each, seed " << options.seed
            << (options.curve_trials > 0 ? ", curves " + std::to_string(options.curve_trials) + " trials"
                                         : "")
            << "\n";
  if (!hglasm::runSuccessRatio(scans, options, &report, &error, progress)) {
    failRuntime(error);
    return kExitRuntimeError;
  }
  std::cerr << "success_ratio: " << report.scans_used << " of " << report.scans_total << " scans usable, "
            << report.scans_skipped << " skipped (fewer than " << options.min_points_per_half
            << " valid points in the odd or even beams); " << report.rows.size() << " rows in " << elapsed()
            << " s\n";

  if (!hglasm::writeSuccessRatioCsv(args.csv, report.rows, &error)) {
    failRuntime(error);
    return kExitRuntimeError;
  }
  std::cerr << "success_ratio: wrote " << args.csv << "\n";
  if (!report.curve.empty()) {
    const std::string curve_csv =
        args.curve_csv.empty() ? siblingCsv(args.csv, "_evaluations.csv") : args.curve_csv;
    const std::string time_csv =
        args.time_csv.empty() ? siblingCsv(args.csv, "_time_to_reach.csv") : args.time_csv;
    const auto times = hglasm::timeToReach(report.curve, hglasm::timeToReachLevels());
    if (!hglasm::writeEvaluationCurveCsv(curve_csv, report.curve, &error) ||
        !hglasm::writeTimeToReachCsv(time_csv, times, &error)) {
      failRuntime(error);
      return kExitRuntimeError;
    }
    std::cerr << "success_ratio: wrote " << curve_csv << " and " << time_csv << "\n";
  }
  if (!args.plots.empty() && !writePlots(report, args)) return kExitRuntimeError;
  return 0;
}
