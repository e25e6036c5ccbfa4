#include "hglasm_odometry/tools/success_ratio_setup.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "hglasm_odometry/evaluation/carmen_log.h"
#include "hglasm_odometry/evaluation/gnuplot.h"
#include "hglasm_odometry/evaluation/success_ratio_report.h"

namespace hglasm_odometry {
namespace {

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

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) items.push_back(item);
  return items;
}

/// The parser filling *args (which must outlive it).
ArgumentParser makeParser(SuccessRatioArguments* args) {
  ArgumentParser parser("success_ratio", kUsage);
  parser.addFlag("--in-box", &args->in_box);
  parser.addFlag("--quiet", &args->quiet);
  parser.addFlag("--no-ceiling", &args->ceiling, false);
  parser.addOption("--bag", &args->bag);
  parser.addOption("--topic", &args->topic, &args->topic_given);
  parser.addOption("--carmen", &args->carmen);
  parser.addOption("--trials", &args->trials, 1);
  parser.addOption("--seed", &args->seed, std::uint64_t{0}, &args->seed_given);
  parser.addOption("--csv", &args->csv);
  parser.addOption("--plots", &args->plots);
  parser.addOption("--algorithms", &args->algorithms);
  parser.addOption("--presets", &args->presets);
  parser.addOption("--cases", &args->cases);
  parser.addOption("--curve-trials", &args->curve_trials, 0);
  parser.addOption("--curve-generations", &args->curve_generations);
  parser.addOption("--curve-csv", &args->curve_csv);
  parser.addOption("--max-scans", &args->max_scans);
  parser.addOption("--min-points", &args->min_points, 3);
  BeamAngleOverrides& beams = args->beam_angles;
  parser.addOption("--angle-min", &beams.angle_min, &beams.angle_min_given);
  parser.addOption("--angle-increment", [&beams](const std::string& text, std::string* error) {
    char* end = nullptr;
    beams.angle_increment = std::strtod(text.c_str(), &end);
    beams.angle_increment_given =
        !text.empty() && *end == '\0' && std::isfinite(beams.angle_increment) && beams.angle_increment != 0.0;
    if (!beams.angle_increment_given) *error = "expected a non-zero number, got '" + text + "'";
    return beams.angle_increment_given;
  });
  parser.addOption("--title", &args->title);
  parser.addOption("--curve-algorithms", &args->curve_algorithms);
  parser.addOption("--time-csv", &args->time_csv);
  parser.addOption("--interlace-seconds", &args->interlace_seconds);
  return parser;
}

/// The checks across options, after parsing.
bool checkArguments(const SuccessRatioArguments& args, const ArgumentParser& parser) {
  if (args.bag.empty() == args.carmen.empty())
    return parser.fail("give exactly one of --bag PATH or --carmen PATH");
  if (args.topic_given && args.bag.empty()) return parser.fail("--topic applies to --bag only");
  if (args.trials == 0) return parser.fail("--trials N is required");
  if (!args.seed_given) return parser.fail("--seed S is required");
  if (args.csv.empty()) return parser.fail("--csv PATH is required");
  if (args.interlace_seconds != 0.0 && args.bag.empty())
    return parser.fail("--interlace-seconds needs --bag (the turn rate comes from its wheel odometry)");
  return true;
}

bool parseAlgorithms(const ArgumentParser& parser, const std::string& flag, const std::string& list,
                     std::vector<hglasm::Algorithm>* algorithms) {
  algorithms->clear();
  for (const std::string& name : splitList(list)) {
    hglasm::Algorithm algorithm;
    if (!hglasm::parseAlgorithm(name, &algorithm)) {
      return parser.fail(flag + ": unknown algorithm '" + name +
                         "' (hglasm_g, hglasm_binary, glasm_g, glasm_binary, mbicp, pga, hpga)");
    }
    if (std::find(algorithms->begin(), algorithms->end(), algorithm) == algorithms->end())
      algorithms->push_back(algorithm);
  }
  return true;
}

bool parsePresets(const ArgumentParser& parser, const std::string& list,
                  std::vector<hglasm::Preset>* presets) {
  for (const std::string& name : splitList(list)) {
    hglasm::Preset preset;
    if (!hglasm::parsePreset(name, &preset))
      return parser.fail("unknown preset '" + name + "' (small, medium, large)");
    if (std::find(presets->begin(), presets->end(), preset) == presets->end()) presets->push_back(preset);
  }
  return true;
}

bool parseGenerations(const ArgumentParser& parser, const std::string& list,
                      std::vector<int>* generations_list) {
  for (const std::string& item : splitList(list)) {
    int generations = 0;
    const char* end = item.data() + item.size();
    const auto parsed = std::from_chars(item.data(), end, generations);
    if (item.empty() || parsed.ec != std::errc() || parsed.ptr != end || generations < 1) {
      return parser.fail("--curve-generations: expected positive integers, got '" + item + "'");
    }
    generations_list->push_back(generations);
  }
  return true;
}

bool buildOptions(const SuccessRatioArguments& args, const ArgumentParser& parser,
                  hglasm::SuccessRatioOptions* options) {
  if (!parseAlgorithms(parser, "--algorithms", args.algorithms, &options->algorithms)) return false;
  if (!parseAlgorithms(parser, "--curve-algorithms", args.curve_algorithms, &options->curve_algorithms))
    return false;
  for (hglasm::Algorithm algorithm : options->curve_algorithms) {
    if (hglasm::usesMbicpStage(algorithm) || !hglasm::usesGeneticStage(algorithm))
      return parser.fail(
          "--curve-algorithms: the curves are of GA-alone algorithms (glasm_g, glasm_binary, pga)");
  }
  options->ceiling = args.ceiling;
  if (!parsePresets(parser, args.presets, &options->presets)) return false;
  if (options->algorithms.empty()) return parser.fail("--algorithms: empty list");
  if (options->presets.empty()) return parser.fail("--presets: empty list");
  std::string error;
  if (!hglasm::parseCases(args.cases, &options->cases, &error)) return parser.fail("--cases: " + error);
  if (options->cases.empty() && !args.in_box && args.curve_trials == 0) {
    return parser.fail("nothing to run: --cases none without --in-box and with --curve-trials 0");
  }
  if (!parseGenerations(parser, args.curve_generations, &options->curve_generations)) return false;
  options->in_box = args.in_box;
  options->trials = args.trials;
  options->seed = args.seed;
  options->min_points_per_half = args.min_points;
  options->curve_trials = args.curve_trials < 0 ? args.trials : args.curve_trials;
  return true;
}

bool readCarmenScans(const SuccessRatioArguments& args, std::vector<hglasm::RangeScan>* scans,
                     std::ostream& log, std::string* error) {
  hglasm::CarmenLogOptions log_options;
  log_options.max_scans = args.max_scans;
  hglasm::CarmenLog carmen;
  if (!hglasm::readCarmenLog(args.carmen, log_options, &carmen, error)) return false;
  log << "success_ratio: read " << carmen.scans.size() << " FLASER scans from " << args.carmen;
  if (carmen.malformed_lines > 0) {
    log << " (" << carmen.malformed_lines << " malformed lines skipped, first at line "
        << carmen.first_malformed_line << ")";
  }
  log << "\n";
  for (const hglasm::CarmenLaserReading& reading : carmen.scans) scans->push_back(reading.ranges);
  return true;
}

bool readBagScans(const SuccessRatioArguments& args, std::vector<hglasm::RangeScan>* scans,
                  std::vector<hglasm::Pose2D>* half_offsets, std::ostream& log, std::string* error) {
  BagReadOptions bag_options;
  bag_options.scan_topic = args.topic;
  if (args.interlace_seconds == 0.0) bag_options.odom_topic.clear();  // only the scans matter here
  bag_options.max_scans = args.max_scans;
  BagData data;
  if (!readBag(args.bag, bag_options, &data, error)) return false;
  log << "success_ratio: read " << data.scans.size() << " scans on " << args.topic << " from " << args.bag
      << "\n";
  if (args.interlace_seconds != 0.0) {
    if (data.odometry.size() < 2) {
      *error = "--interlace-seconds: the bag has no wheel odometry";
      return false;
    }
    for (const BagScan& scan : data.scans) {
      half_offsets->push_back(hglasm::halfScanOffset(baseVelocityAt(data.odometry, scan.stamp),
                                                     data.base_to_laser, args.interlace_seconds));
    }
    log << "success_ratio: truths offset by the laser's motion over " << args.interlace_seconds
        << " s (wheel odometry, " << data.odometry.size() << " samples)\n";
  }
  for (BagScan& scan : data.scans) scans->push_back(std::move(scan.ranges));
  return true;
}

bool writePlots(const SuccessRatioArguments& args, const hglasm::SuccessRatioReport& report,
                std::ostream& log, std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(args.plots, ec);
  if (ec) {
    *error = "cannot create plot directory '" + args.plots + "': " + ec.message();
    return false;
  }
  std::string title = args.title;
  if (title.empty())
    title = std::filesystem::path(args.bag.empty() ? args.carmen : args.bag).filename().string();
  std::vector<std::string> scripts;
  if (!hglasm::writeSuccessRatioPlotScripts(report, args.plots, title, &scripts, error)) return false;
  if (scripts.empty()) {
    log << "success_ratio: nothing to plot (success plots need >= 2 rotation errors, curves need "
           "--curve-trials > 0)\n";
    return true;
  }
  for (const std::string& script : scripts) {
    if (!hglasm::runGnuplot(script)) {
      *error = "gnuplot failed on " + script + " (is gnuplot installed? Debian package gnuplot-nox)";
      return false;
    }
    log << "success_ratio: wrote " << script.substr(0, script.size() - 3) << ".png\n";
  }
  return true;
}

}  // namespace

ArgumentParser::Result parseSuccessRatioArguments(const std::vector<std::string>& arguments,
                                                  SuccessRatioArguments* args,
                                                  hglasm::SuccessRatioOptions* options) {
  const ArgumentParser parser = makeParser(args);
  const ArgumentParser::Result result = parser.parse(arguments);
  if (result != ArgumentParser::Result::kOk) return result;
  if (!checkArguments(*args, parser) || !buildOptions(*args, parser, options))
    return ArgumentParser::Result::kError;
  return ArgumentParser::Result::kOk;
}

Eigen::Vector3d baseVelocityAt(const std::vector<BagOdometry>& odometry, double stamp) {
  if (odometry.size() < 2) return Eigen::Vector3d::Zero();
  const auto after = std::upper_bound(odometry.begin(), odometry.end(), stamp,
                                      [](double t, const BagOdometry& o) { return t < o.stamp; });
  std::size_t next = static_cast<std::size_t>(after - odometry.begin());
  next = std::clamp<std::size_t>(next, 1, odometry.size() - 1);
  const BagOdometry& a = odometry[next - 1];
  const BagOdometry& b = odometry[next];
  const double dt = b.stamp - a.stamp;
  if (!(dt > 0.0)) return Eigen::Vector3d::Zero();
  const hglasm::Pose2D motion = hglasm::relativePose(a.pose, b.pose);
  return Eigen::Vector3d(motion.x, motion.y, motion.theta) / dt;
}

bool readSuccessRatioScans(const SuccessRatioArguments& args, std::vector<hglasm::RangeScan>* scans,
                           std::vector<hglasm::Pose2D>* half_offsets, std::ostream& log, std::string* error) {
  const bool read = args.carmen.empty() ? readBagScans(args, scans, half_offsets, log, error)
                                        : readCarmenScans(args, scans, log, error);
  if (!read) return false;
  if (scans->empty()) {
    *error = "no scans read";
    return false;
  }
  for (hglasm::RangeScan& scan : *scans) args.beam_angles.applyTo(&scan);
  return true;
}

std::string siblingCsv(const std::string& csv, const std::string& tail) {
  const std::string suffix = ".csv";
  if (csv.size() > suffix.size() && csv.compare(csv.size() - suffix.size(), suffix.size(), suffix) == 0) {
    return csv.substr(0, csv.size() - suffix.size()) + tail;
  }
  return csv + tail;
}

bool prepareSuccessRatioOutputs(const SuccessRatioArguments& args, std::string* error) {
  if (!std::ofstream(args.csv, std::ios::app)) {
    *error = "cannot write '" + args.csv + "'";
    return false;
  }
  std::error_code ec;
  if (!args.plots.empty()) std::filesystem::create_directories(args.plots, ec);
  if (ec) *error = "cannot create plot directory '" + args.plots + "': " + ec.message();
  return !ec;
}

bool writeSuccessRatioOutputs(const SuccessRatioArguments& args, const hglasm::SuccessRatioReport& report,
                              std::ostream& log, std::string* error) {
  if (!hglasm::writeSuccessRatioCsv(args.csv, report.rows, error)) return false;
  log << "success_ratio: wrote " << args.csv << "\n";
  if (!report.curve.empty()) {
    const std::string curve_csv =
        args.curve_csv.empty() ? siblingCsv(args.csv, "_evaluations.csv") : args.curve_csv;
    const std::string time_csv =
        args.time_csv.empty() ? siblingCsv(args.csv, "_time_to_reach.csv") : args.time_csv;
    const auto times = hglasm::timeToReach(report.curve, hglasm::timeToReachLevels());
    if (!hglasm::writeEvaluationCurveCsv(curve_csv, report.curve, error) ||
        !hglasm::writeTimeToReachCsv(time_csv, times, error)) {
      return false;
    }
    log << "success_ratio: wrote " << curve_csv << " and " << time_csv << "\n";
  }
  return args.plots.empty() || writePlots(args, report, log, error);
}

}  // namespace hglasm_odometry
