// What the evaluate tool does before its run: its command line, the nodelet's options from the package's
// YAML through the nodelet's loader, and the bag and relations it reads.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/evaluation/relations.h"
#include "hglasm_odometry/ros/parameters.h"
#include "hglasm_odometry/tools/argument_parser.h"
#include "hglasm_odometry/tools/bag_reader.h"

namespace hglasm_odometry {

struct EvaluateArguments {
  std::string bag;
  std::string scan_topic = "/scan";
  std::string odom_topic = "/odom";
  std::string config;  ///< empty until given or found (defaultConfigPath)
  bool config_given = false;
  std::string presets;  ///< empty: presets.yaml next to the config
  bool presets_given = false;
  std::string preset;
  std::string relations;
  std::string out, trace, plot, map;
  std::string relation_errors;  ///< --relation-errors: per-relation errors of both trajectories
  bool use_odometry = true;
  double min_scan_interval = 0.0;
  double pace_rate = 0.0;  ///< --pace: process the scans no faster than rosbag play at this rate
  bool override_mount = false;
  hglasm::Pose2D laser_mount;
  std::size_t max_scans = 0;
  double odom_stamp_shift = 0.0;
  BeamAngleOverrides beam_angles;
  double short_span = 10.0;
  bool direct_pairs = false;
  bool blend_wheels = false;
  bool quiet = false;
};

/// kOk with *args filled, or what the tool should exit with (the usage or the problem printed).
ArgumentParser::Result parseEvaluateArguments(const std::vector<std::string>& arguments,
                                              EvaluateArguments* args);

/// X,Y,YAW (metres, metres, radians) into a pose.
bool parseLaserMount(const std::string& text, hglasm::Pose2D* mount, std::string* error);

/// The installed (or devel-space) package's config/laser_odometry.yaml, found as roslaunch finds
/// $(find hglasm_odometry): through ROS_PACKAGE_PATH, so no source path is compiled in.
bool defaultConfigPath(std::string* path, std::string* error);

/// presets.yaml in the directory of `config`.
std::string presetsNextTo(const std::string& config);

/// The nodelet's private namespace as the launch files build it (presets.yaml under ~presets,
/// laser_odometry.yaml at the top, then --preset) read by the nodelet's loader. Files named on the command
/// line must exist; an absent default file means built-in defaults (*config_found false for the config).
bool loadEvaluateOptions(const EvaluateArguments& args, LaserOdometryOptions* options,
                         std::vector<std::string>* warnings, bool* config_found, std::string* error);

/// What evaluate runs on and scores against.
struct EvaluateInputs {
  BagData data;  ///< with the arguments' overrides: laser mount, beam angles, wheels moved later
  std::vector<hglasm::Relation> relations;
  double read_cpu_seconds = 0.0;  ///< reading the bag (process CPU)
  std::string mount_source;       ///< where data.base_to_laser came from
};

bool readEvaluateInputs(const EvaluateArguments& args, const std::string& base_frame, EvaluateInputs* inputs,
                        std::string* error);

}  // namespace hglasm_odometry
