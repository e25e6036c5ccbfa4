#include "hglasm_odometry/tools/evaluate_setup.h"

#include <algorithm>
#include <cmath>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <ros/package.h>

#include "hglasm_odometry/core/timing.h"
#include "hglasm_odometry/tools/yaml_parameters.h"

namespace hglasm_odometry {
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
    "  --relation-errors F     write one line per relation (with --relations): the reference's motion and\n"
    "                          the laser's and the wheels' signed residuals and errors on it\n"
    "  --plot F.png            plot laser and wheel odometry trajectories (gnuplot)\n"
    "  --map F.png             draw every scan at the laser odometry's poses beside the same scans at the\n"
    "                          wheel odometry's (gnuplot; metre grid, equal axis scale)\n"
    "  --no-odom               do not feed wheel odometry to the tracker (constant-velocity prior)\n"
    "  --min-scan-interval S   skip scans stamped less than S s after the last processed one\n"
    "  --laser-mount X,Y,YAW   base -> laser (m, m, rad) instead of the bag's tf\n"
    "  --max-scans N           process only the first N scans\n"
    "  --pace RATE             process each scan no earlier than rosbag play --rate RATE delivers it to\n"
    "                          a live node (the CPU per scan of a core that idles between scans, as\n"
    "                          the node's worker does; scripts/node_cpu.sh); default: as fast as it goes\n"
    "  --odom-stamp-shift S    move every wheel-odometry message S s later (stamp and arrival): wheels that\n"
    "                          lag the scans by S s, for the time-offset estimation (the wheel baseline\n"
    "                          is read S s later too, so it stays the bag's)\n"
    "  --angle-increment A     override the scans' angle increment (radians)\n"
    "  --angle-min A           override the scans' first beam angle (radians)\n"
    "  --max-span S            short-relation span for the second metric row (default 10 s)\n"
    "  --direct-pairs          also match each relation's own scan pair directly (MbICP started from the\n"
    "                          reference motion): how closely any one-shot match of the very scans the\n"
    "                          reference aligned can agree with it, the floor of the relations metric;\n"
    "                          and the relations those scans and the wheels agree against (> 3 deg off\n"
    "                          the reference's turn, within 1 deg of each other), and the metric\n"
    "                          without them\n"
    "  --blend-wheels          also score the laser odometry's steps blended with the wheels' at fixed\n"
    "                          weights (0, 0.25 ... 1 for translation and heading): would any fixed\n"
    "                          re-weighting of the two inputs serve the relations better than the fusion\n"
    "  --quiet                 no per-warning output\n";

constexpr double kMinPaceRate = 0.01;  // slower, a bag's hours would overflow the wall clock's ticks

bool exists(const std::string& path) { return std::ifstream(path).good(); }

/// Whether every parameter of `tree` is `key` or below it (and there is one).
bool onlyKey(const hglasm::ParameterTree& tree, const std::string& key) {
  const auto& values = tree.values();
  return !values.empty() && std::all_of(values.begin(), values.end(), [&key](const auto& entry) {
    return entry.first == key || entry.first.compare(0, key.size() + 1, key + "/") == 0;
  });
}

}  // namespace

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

ArgumentParser::Result parseEvaluateArguments(const std::vector<std::string>& arguments,
                                              EvaluateArguments* args) {
  ArgumentParser parser("evaluate", kUsage);
  parser.addOption("--bag", &args->bag);
  parser.addOption("--scan-topic", &args->scan_topic);
  parser.addOption("--odom-topic", &args->odom_topic);
  parser.addOption("--config", &args->config, &args->config_given);
  parser.addOption("--presets", &args->presets, &args->presets_given);
  parser.addOption("--preset", &args->preset);
  parser.addOption("--relations", &args->relations);
  parser.addOption("--out", &args->out);
  parser.addOption("--trace", &args->trace);
  parser.addOption("--relation-errors", &args->relation_errors);
  parser.addOption("--plot", &args->plot);
  parser.addOption("--map", &args->map);
  parser.addFlag("--no-odom", &args->use_odometry, false);
  parser.addFlag("--quiet", &args->quiet);
  parser.addFlag("--direct-pairs", &args->direct_pairs);
  parser.addFlag("--blend-wheels", &args->blend_wheels);
  parser.addOption("--max-scans", &args->max_scans);
  parser.addOption("--odom-stamp-shift", &args->odom_stamp_shift);
  parser.addOption("--angle-increment", &args->beam_angles.angle_increment,
                   &args->beam_angles.angle_increment_given);
  parser.addOption("--angle-min", &args->beam_angles.angle_min, &args->beam_angles.angle_min_given);
  parser.addOption("--laser-mount", [args](const std::string& text, std::string* error) {
    args->override_mount = parseLaserMount(text, &args->laser_mount, error);
    return args->override_mount;
  });
  parser.addOption("--min-scan-interval", &args->min_scan_interval);
  parser.addOption("--pace", &args->pace_rate);
  parser.addOption("--max-span", &args->short_span);
  const ArgumentParser::Result result = parser.parse(arguments);
  if (result != ArgumentParser::Result::kOk) return result;
  if (args->bag.empty()) {
    parser.fail("--bag is required");
    return ArgumentParser::Result::kError;
  }
  if (!(args->pace_rate == 0.0 || args->pace_rate >= kMinPaceRate) || !std::isfinite(args->pace_rate)) {
    parser.fail("--pace must be a playback rate of at least 0.01 (or 0: as fast as it goes)");
    return ArgumentParser::Result::kError;
  }
  if (!args->relation_errors.empty() && args->relations.empty()) {
    parser.fail("--relation-errors needs --relations");
    return ArgumentParser::Result::kError;
  }
  return ArgumentParser::Result::kOk;
}

bool defaultConfigPath(std::string* path, std::string* error) {
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

std::string presetsNextTo(const std::string& config) {
  const auto slash = config.find_last_of('/');
  return (slash == std::string::npos ? std::string() : config.substr(0, slash + 1)) + "presets.yaml";
}

bool loadEvaluateOptions(const EvaluateArguments& args, LaserOdometryOptions* options,
                         std::vector<std::string>* warnings, bool* config_found, std::string* error) {
  hglasm::ParameterTree root, presets;
  *config_found = args.config_given || exists(args.config);
  if (*config_found && !loadYamlParameters(args.config, &root, error)) return false;
  const std::string presets_path = args.presets.empty() ? presetsNextTo(args.config) : args.presets;
  if (args.presets_given || exists(presets_path)) {
    if (!loadYamlParameters(presets_path, &presets, error)) return false;
    // Accept a presets file written either as {small: ..} or as {presets: {small: ..}}.
    hglasm::ParameterValue nested;
    if (onlyKey(presets, "presets") && presets.find("presets", &nested) &&
        nested.type != hglasm::ParameterValue::Type::kDictionary) {
      root.set("presets", nested);  // not a dictionary: the loader says so
    } else {
      root.setTree("presets", onlyKey(presets, "presets") ? presets.subtree("presets") : presets);
    }
  }
  if (!args.preset.empty()) root.set("preset", hglasm::ParameterValue::ofString(args.preset));
  return loadOptions(root, options, error, warnings);
}

bool readEvaluateInputs(const EvaluateArguments& args, const std::string& base_frame, EvaluateInputs* inputs,
                        std::string* error) {
  BagReadOptions read_options;
  read_options.scan_topic = args.scan_topic;
  read_options.odom_topic = args.odom_topic;
  read_options.max_scans = args.max_scans;
  read_options.base_frame = base_frame;
  const double read_start = hglasm::processCpuMs();
  BagData& data = inputs->data;
  if (!readBag(args.bag, read_options, &data, error)) return false;
  if (!args.relations.empty() && !hglasm::readRelations(args.relations, &inputs->relations, error))
    return false;
  inputs->read_cpu_seconds = (hglasm::processCpuMs() - read_start) * 1e-3;
  inputs->mount_source = data.has_laser_mount ? "from tf" : "not found, identity";
  if (args.override_mount) {
    data.has_laser_mount = true;
    data.base_to_laser = args.laser_mount;
    inputs->mount_source = "from --laser-mount";
  }
  for (BagScan& scan : data.scans) args.beam_angles.applyTo(&scan.ranges);
  if (args.odom_stamp_shift != 0.0) shiftOdometry(args.odom_stamp_shift, &data);
  return true;
}

}  // namespace hglasm_odometry
