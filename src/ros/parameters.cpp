#include "hglasm_odometry/ros/parameters.h"

#include <sstream>

#include <ros/names.h>

#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/ros/conversions.h"

namespace hglasm_odometry {
namespace {

using hglasm::OptionReader;
using hglasm::ParameterSource;
using hglasm::ParameterValue;
using XmlRpc::XmlRpcValue;

/// A value's type and, for a scalar, its value (a list's or dictionary's contents stay in the tree).
ParameterValue typed(const XmlRpcValue& node) {
  XmlRpcValue copy;  // the typed conversions of XmlRpcValue are not const
  switch (node.getType()) {
    case XmlRpcValue::TypeBoolean:
      return ParameterValue::ofBool(static_cast<bool>(copy = node));
    case XmlRpcValue::TypeInt:
      return ParameterValue::ofInt(static_cast<int>(copy = node));
    case XmlRpcValue::TypeDouble:
      return ParameterValue::ofDouble(static_cast<double>(copy = node));
    case XmlRpcValue::TypeString:
      return ParameterValue::ofString(static_cast<std::string>(copy = node));
    case XmlRpcValue::TypeArray:
      return ParameterValue::ofType(ParameterValue::Type::kList);
    case XmlRpcValue::TypeStruct:
      return ParameterValue::ofType(ParameterValue::Type::kDictionary);
    default:
      return ParameterValue();
  }
}

XmlRpcValue xmlRpcOf(const ParameterValue& value) {
  switch (value.type) {
    case ParameterValue::Type::kBool:
      return XmlRpcValue(value.boolean);
    case ParameterValue::Type::kInt:
      return XmlRpcValue(value.integer);
    case ParameterValue::Type::kDouble:
      return XmlRpcValue(value.number);
    case ParameterValue::Type::kString:
      return XmlRpcValue(value.text);
    default:
      break;  // the writer writes scalars only
  }
  XmlRpcValue dictionary;
  dictionary.begin();  // an empty struct
  return dictionary;
}

void collectLeaves(const XmlRpcValue& node, const std::string& path, std::vector<std::string>* leaves) {
  if (node.getType() != XmlRpcValue::TypeStruct) {
    if (!path.empty()) leaves->push_back(path);
    return;
  }
  for (auto it = node.begin(); it != node.end(); ++it) {
    collectLeaves(it->second, path.empty() ? it->first : path + "/" + it->first, leaves);
  }
}

/// Constraints between parameters, checked once all layers are applied.
bool checkConsistency(const LaserOdometryOptions& options, std::string* error) {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const std::string tracker = hglasm::inconsistency(options.tracker, "~");
  if (!tracker.empty()) return fail(tracker);
  const DiagnosticsOptions& diagnostics = options.diagnostics;
  if (diagnostics.error_failure_ratio < diagnostics.warn_failure_ratio) {
    return fail(hglasm::constraintError("~", "diagnostics/error_failure_ratio", "be at least",
                                        "diagnostics/warn_failure_ratio",
                                        ParameterValue::ofDouble(diagnostics.warn_failure_ratio),
                                        ParameterValue::ofDouble(diagnostics.error_failure_ratio)));
  }
  if (options.odom_frame.empty() || options.base_frame.empty() || options.odom_frame == options.base_frame) {
    return fail("parameter ~base_frame must differ from ~odom_frame and neither may be \"/\", got \"" +
                options.base_frame + "\" and \"" + options.odom_frame + "\"");
  }
  return true;
}

/// ~algorithm chose among the papers' matchers; a baseline is no longer what the odometry can run.
constexpr const char* kAlgorithmRemoved =
    "the odometry always runs hglasm_g; the papers' other algorithms are compared by the success_ratio tool "
    "(--algorithms); delete the parameter";

/// What a user is told of a parameter nobody reads: a retired one says what replaced it.
std::string unknownParameterWarning(const std::string& path) {
  if (path == "~max_time_jump") {
    return "parameter ~max_time_jump is no longer used (ignored): a forward gap in the scans' stamps of any "
           "length continues from the current pose; only a clock that jumps back by more than "
           "~time/reset_on_jump_back resets";
  }
  return "unknown parameter " + path + " (ignored)";
}

/// Layer 1: the built-in values of the preset ~preset names. *in_yaml: ~presets/<name> exists (layer 2).
bool startFromPreset(const ParameterSource& params, OptionReader& top, LaserOdometryOptions* options,
                     bool* in_yaml, std::string* error) {
  std::string preset_name = options->preset;
  if (!top.text("preset", &preset_name) && top.failed()) return false;
  ParameterValue presets;
  const bool has_presets = top.find("presets", &presets);
  if (has_presets && presets.type != ParameterValue::Type::kDictionary) {
    if (error) *error = "parameter ~presets must be a dictionary of presets, got " + presets.describe();
    return false;
  }
  ParameterValue preset_tree;
  const bool preset_in_yaml = has_presets && preset_name.find('/') == std::string::npos &&
                              params.find("presets/" + preset_name, &preset_tree);
  hglasm::Preset builtin = hglasm::Preset::kMedium;  // what a preset defined in YAML alone builds on
  if (!hglasm::parsePreset(preset_name, &builtin) && !preset_in_yaml) {
    if (error) {
      *error =
          "parameter ~preset must be one of small, medium, large (or a preset defined under ~presets), "
          "got string \"" +
          preset_name + "\"";
    }
    return false;
  }
  options->preset = preset_name;
  options->tracker.matcher = hglasm::presetOptions(builtin);
  *in_yaml = preset_in_yaml;
  return true;
}

/// Layer 2: ~presets/<name> (config/presets.yaml).
bool applyPresetTree(const ParameterSource& params, LaserOdometryOptions* options, std::string* error,
                     std::vector<std::string>* warnings) {
  const std::string prefix = "~presets/" + options->preset;
  ParameterValue preset_tree;
  params.find("presets/" + options->preset, &preset_tree);
  if (preset_tree.type != ParameterValue::Type::kDictionary) {
    if (error) *error = "parameter " + prefix + " must be a dictionary, got " + preset_tree.describe();
    return false;
  }
  const hglasm::SubtreeSource preset_params(params, "presets/" + options->preset + "/");
  OptionReader preset(preset_params, prefix + "/");
  visitOptions(preset, options);
  preset.removed("algorithm", kAlgorithmRemoved);
  if (preset.failed()) {
    if (error) *error = preset.error();
    return false;
  }
  if (warnings) {
    for (const std::string& path : preset.unknownPaths())
      warnings->push_back("unknown parameter " + path + " (ignored)");
  }
  return true;
}

}  // namespace

std::string normalizeFrame(std::string* frame) {
  *frame = stripLeadingSlash(*frame);
  return "";
}

std::string checkTopic(std::string* topic) {
  std::string why;
  if ((*topic)[0] == '~' || !ros::names::validate(*topic, why)) return "a relative or absolute topic name";
  return "";
}

bool XmlRpcParameterSource::find(const std::string& path, ParameterValue* value) const {
  const XmlRpcValue* node = &root_;
  std::size_t start = 0;
  while (true) {
    const std::size_t slash = path.find('/', start);
    const std::string key =
        path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (node->getType() != XmlRpcValue::TypeStruct || !node->hasMember(key)) return false;
    node = &(*node)[key];
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  *value = typed(*node);
  return true;
}

std::vector<std::string> XmlRpcParameterSource::leafPaths() const {
  std::vector<std::string> leaves;
  collectLeaves(root_, "", &leaves);
  return leaves;
}

bool loadOptions(const ParameterSource& private_params, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings) {
  OptionReader top(private_params, "~");
  *options = LaserOdometryOptions();
  bool preset_in_yaml = false;
  if (!startFromPreset(private_params, top, options, &preset_in_yaml, error)) {
    if (error && top.failed()) *error = top.error();
    return false;
  }
  if (preset_in_yaml && !applyPresetTree(private_params, options, error, warnings)) return false;

  // Layer 3: the top level (config/laser_odometry.yaml, single overrides).
  visitOptions(top, options);
  top.removed("algorithm", kAlgorithmRemoved);
  if (top.failed()) {
    if (error) *error = top.error();
    return false;
  }
  if (!checkConsistency(*options, error)) return false;
  if (warnings) {
    // diagnostic_period belongs to diagnostic_updater, which reads it from the same namespace.
    for (const std::string& path : top.unknownPaths({"presets", "diagnostic_period"})) {
      warnings->push_back(unknownParameterWarning(path));
    }
  }
  return true;
}

bool loadOptions(const XmlRpcValue& private_params, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings) {
  // An invalid (empty) value means no parameters at all: every default applies.
  if (private_params.getType() != XmlRpcValue::TypeStruct &&
      private_params.getType() != XmlRpcValue::TypeInvalid) {
    if (error) {
      *error = "the private namespace must hold a dictionary of parameters, got " +
               typed(private_params).describe();
    }
    return false;
  }
  return loadOptions(XmlRpcParameterSource(private_params), options, error, warnings);
}

hglasm::ParameterTree toParameterTree(const LaserOdometryOptions& options) {
  hglasm::ParameterTree tree;
  hglasm::OptionWriter writer(&tree);
  LaserOdometryOptions copy = options;  // the visitor reads through non-const pointers
  visitOptions(writer, &copy);
  return tree;
}

XmlRpcValue toParams(const LaserOdometryOptions& options) {
  XmlRpcValue params;
  const hglasm::ParameterTree tree = toParameterTree(options);
  for (const auto& entry : tree.values()) {
    const std::string& path = entry.first;
    XmlRpcValue* node = &params;
    std::size_t start = 0;
    for (std::size_t slash; (slash = path.find('/', start)) != std::string::npos; start = slash + 1) {
      node = &(*node)[path.substr(start, slash - start)];
    }
    (*node)[path.substr(start)] = xmlRpcOf(entry.second);
  }
  return params;
}

bool loadOptions(const ros::NodeHandle& private_nh, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings) {
  XmlRpcValue params;
  if (!private_nh.getParam(private_nh.getNamespace(), params)) params = XmlRpcValue();
  return loadOptions(params, options, error, warnings);
}

std::string summarize(const LaserOdometryOptions& options) {
  const hglasm::MatcherOptions& matcher = options.tracker.matcher;
  const hglasm::GeneticOptions& genetic = matcher.genetic;
  std::ostringstream out;
  out << "preset " << options.preset << ", box +-" << genetic.box.half_x << " m x +-" << genetic.box.half_y
      << " m x +-" << genetic.box.half_theta << " rad, GA " << genetic.population << "x"
      << genetic.generations << "x" << genetic.runs << ", cell " << matcher.table.cell_size << " m, keyframe "
      << options.tracker.keyframe.distance << " m / " << options.tracker.keyframe.angle << " rad, "
      << options.odom_frame << " -> " << options.base_frame << (options.publish_tf ? " (tf)" : " (no tf)")
      << (options.tracker.prediction.use_odometry ? ", wheel odometry in" : ", no wheel odometry")
      << (options.tracker.prediction.use_imu
              ? (options.tracker.prediction.imu.use_orientation ? ", IMU orientation in" : ", IMU rate in")
              : "")
      << ", queue " << options.queue_size;
  return out.str();
}

}  // namespace hglasm_odometry
