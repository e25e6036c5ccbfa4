// The shipped YAML agrees with the code's defaults: config/laser_odometry.yaml and config/presets.yaml,
// loaded as the launch file loads them and read by the nodelet's own loader, give every option the value it
// has with no YAML at all (the C++ defaults, presetOptions() for the matcher). laser_odometry.yaml writes
// every option but the matcher's once; presets.yaml only what each preset changes from the matcher's
// defaults; neither writes an option in a comment.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/ros/parameters.h"

namespace hglasm_odometry {
namespace {

using XmlRpc::XmlRpcValue;

const std::string kConfig = HGLASM_SOURCE_DIR "/config/laser_odometry.yaml";
const std::string kPresets = HGLASM_SOURCE_DIR "/config/presets.yaml";
const char* const kPresetNames[] = {"small", "medium", "large"};

/// A YAML file as roslaunch's <rosparam file=...> loads it: by rosparam itself, over XML-RPC.
XmlRpcValue loadYaml(const std::string& path) {
  setenv("HGLASM_TEST_YAML", path.c_str(), 1);  // no shell quoting of the path
  FILE* pipe = popen(
      "/usr/bin/python3 -c 'import os, sys, xmlrpc.client, rosparam\n"
      "params = rosparam.load_file(os.environ[\"HGLASM_TEST_YAML\"])[0][0]\n"
      "sys.stdout.write(xmlrpc.client.dumps((params,)))'",
      "r");
  std::string xml;
  char buffer[4096];
  for (std::size_t n; pipe && (n = fread(buffer, 1, sizeof(buffer), pipe)) > 0;) xml.append(buffer, n);
  if (!pipe || pclose(pipe) != 0 || xml.find("<value>") == std::string::npos) {
    ADD_FAILURE() << "rosparam could not load " << path;
    return XmlRpcValue();
  }
  int offset = static_cast<int>(xml.find("<value>"));
  return XmlRpcValue(xml, &offset);
}

/// The private namespace the launch file builds: presets.yaml under ~presets, laser_odometry.yaml on top.
XmlRpcValue shippedParams(const std::string& preset) {
  XmlRpcValue root = loadYaml(kConfig);
  root["presets"] = loadYaml(kPresets);
  root["preset"] = preset;
  return root;
}

/// Every leaf of a parameter tree as "path" -> "type value" (doubles to the last bit).
void flatten(const XmlRpcValue& node, const std::string& path, std::map<std::string, std::string>* out) {
  XmlRpcValue value = node;  // the typed conversions of XmlRpcValue are not const
  std::ostringstream text;
  switch (value.getType()) {
    case XmlRpcValue::TypeStruct:
      for (auto it = value.begin(); it != value.end(); ++it) {
        flatten(it->second, path.empty() ? it->first : path + "/" + it->first, out);
      }
      return;
    case XmlRpcValue::TypeBoolean:
      text << "bool " << (static_cast<bool>(value) ? "true" : "false");
      break;
    case XmlRpcValue::TypeInt:
      text << "int " << static_cast<int>(value);
      break;
    case XmlRpcValue::TypeDouble:
      text.precision(17);
      text << "double " << static_cast<double>(value);
      break;
    case XmlRpcValue::TypeString:
      text << "string " << static_cast<std::string>(value);
      break;
    default:
      text << "type " << static_cast<int>(value.getType());
      break;
  }
  (*out)[path] = text.str();
}

std::map<std::string, std::string> flat(const XmlRpcValue& tree) {
  std::map<std::string, std::string> out;
  flatten(tree, "", &out);
  return out;
}

std::set<std::string> keys(const std::map<std::string, std::string>& leaves) {
  std::set<std::string> out;
  for (const auto& leaf : leaves) out.insert(leaf.first);
  return out;
}

/// Each option that differs, one per line ("" if none).
std::string differences(const std::map<std::string, std::string>& got,
                        const std::map<std::string, std::string>& expected) {
  std::string out;
  std::set<std::string> paths = keys(got);
  for (const auto& leaf : expected) paths.insert(leaf.first);
  for (const std::string& path : paths) {
    const auto a = got.find(path), b = expected.find(path);
    const std::string value = a == got.end() ? "(missing)" : a->second;
    const std::string default_value = b == expected.end() ? "(missing)" : b->second;
    if (value != default_value) out += "\n  " + path + ": " + value + ", default " + default_value;
  }
  return out;
}

LaserOdometryOptions load(const XmlRpcValue& params) {
  LaserOdometryOptions options;
  std::string error;
  std::vector<std::string> warnings;
  EXPECT_TRUE(loadOptions(params, &options, &error, &warnings)) << error;
  for (const std::string& warning : warnings) ADD_FAILURE() << warning;
  return options;
}

/// What the code alone says: the struct defaults, with the matcher of the built-in preset.
LaserOdometryOptions codeDefaults(const std::string& preset_name) {
  hglasm::Preset preset;
  EXPECT_TRUE(hglasm::parsePreset(preset_name, &preset));
  LaserOdometryOptions options;
  options.preset = preset_name;
  options.tracker.matcher = hglasm::presetOptions(preset);
  return options;
}

TEST(ShippedYaml, EveryOptionOfEveryPresetIsTheCodeDefault) {
  for (const char* preset : kPresetNames) {
    SCOPED_TRACE(preset);
    const auto expected = flat(toParams(codeDefaults(preset)));
    const LaserOdometryOptions from_yaml = load(shippedParams(preset));
    EXPECT_EQ(from_yaml.preset, preset);
    EXPECT_EQ(differences(flat(toParams(from_yaml)), expected), "");
    XmlRpcValue no_yaml;
    no_yaml["preset"] = preset;
    EXPECT_EQ(differences(flat(toParams(load(no_yaml))), expected), "");
  }
}

TEST(ShippedYaml, TheStructDefaultsAreTheMediumPreset) {
  const auto medium = flat(toParams(codeDefaults("medium")));
  EXPECT_EQ(differences(flat(toParams(LaserOdometryOptions())), medium), "");
  EXPECT_EQ(differences(flat(toParams(load(XmlRpcValue()))), medium), "");
  EXPECT_EQ(LaserOdometryOptions().preset, "medium");
}

/// The matcher's options: set per preset (presets.yaml), or at the top level to override every preset.
bool isMatcherOption(const std::string& path) {
  for (const char* prefix : {"genetic/", "table/", "coarse_table/", "mbicp/"}) {
    if (path.compare(0, std::string(prefix).size(), prefix) == 0) return true;
  }
  return false;
}

TEST(ShippedYaml, TheConfigWritesEveryOptionButTheMatchersOnce) {
  const std::set<std::string> options = keys(flat(toParams(LaserOdometryOptions())));
  std::set<std::string> config = keys(flat(loadYaml(kConfig)));
  EXPECT_EQ(config.erase("preset"), 1u);  // selects the preset; not an option of its own
  for (const std::string& key : options) {
    EXPECT_EQ(config.count(key), isMatcherOption(key) ? 0u : 1u)
        << key
        << (isMatcherOption(key) ? " (the matcher's) would override every preset" : " is not in the YAML");
  }
  for (const std::string& key : config) EXPECT_EQ(options.count(key), 1u) << key << " is not an option";
}

TEST(ShippedYaml, EachPresetWritesOnlyWhatItChangesFromTheDefaults) {
  const auto defaults = flat(toParams(LaserOdometryOptions()));
  XmlRpcValue presets = loadYaml(kPresets);
  for (const char* preset : kPresetNames) {
    SCOPED_TRACE(preset);
    ASSERT_TRUE(presets.hasMember(preset));
    for (const auto& leaf : flat(presets[preset])) {
      EXPECT_TRUE(isMatcherOption(leaf.first)) << leaf.first << " is not the matcher's";
      ASSERT_EQ(defaults.count(leaf.first), 1u) << leaf.first << " is not an option";
      EXPECT_NE(leaf.second, defaults.at(leaf.first)) << leaf.first << " repeats the default";
    }
  }
}

TEST(ShippedYaml, NoOptionIsWrittenInAComment) {
  // A commented "key: value" is a second copy of a default that nothing checks.
  const std::regex commented_option(R"(^\s*#\s*[a-z_]+:(\s|$))");
  for (const std::string& path : {kConfig, kPresets}) {
    std::ifstream file(path);
    ASSERT_TRUE(file.good()) << path;
    std::string line;
    for (int number = 1; std::getline(file, line); ++number) {
      EXPECT_FALSE(std::regex_search(line, commented_option)) << path << ":" << number << ": " << line;
    }
  }
}

}  // namespace
}  // namespace hglasm_odometry
