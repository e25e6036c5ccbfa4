// loadYamlParameters gives exactly what rosparam gives (the same types, the same bits) on the shipped
// configuration and on a file of every kind of scalar it reads, and an error naming the key on what it
// refuses (what rosparam would read otherwise or the parameter server cannot hold); the nodelet's loader
// reads its parameters.
#include "hglasm_odometry/tools/yaml_parameters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "hglasm_odometry/ros/parameters.h"

namespace hglasm_odometry {
namespace {

using hglasm::ParameterValue;
using Type = hglasm::ParameterValue::Type;
using XmlRpc::XmlRpcValue;

const std::string kSourceDir = HGLASM_SOURCE_DIR;

/// rosparam's own loader (what roslaunch's <rosparam command="load"> runs), handed over as XML-RPC, the
/// parameter server's wire format: the reference. False if python3 or rosparam is missing.
bool loadWithRosparam(const std::string& path, XmlRpcValue* value, std::string* output) {
  setenv("HGLASM_TEST_YAML", path.c_str(), 1);  // the path travels in the environment: no quoting
  const char* command =
      "/usr/bin/python3 -c 'import os, sys, xmlrpc.client, rosparam\n"
      "loaded = rosparam.load_file(os.environ[\"HGLASM_TEST_YAML\"])\n"
      "params = (loaded[0][0] if loaded else None) or {}\n"
      "sys.stdout.write(xmlrpc.client.dumps((params,), allow_none=True))' 2>&1";
  FILE* pipe = popen(command, "r");
  if (!pipe) return false;
  char buffer[4096];
  for (std::size_t n; (n = fread(buffer, 1, sizeof(buffer), pipe)) > 0;) output->append(buffer, n);
  const int status = pclose(pipe);
  const auto start = output->find("<value>");
  if (status != 0 || start == std::string::npos) return false;
  int offset = static_cast<int>(start);
  *value = XmlRpcValue(*output, &offset);
  return value->valid();
}

/// Empty if `actual` equals rosparam's `expected_const` in type and value (doubles bit for bit, NaN equal to
/// NaN), else the difference. A dictionary's contents are compared by path (treeDifference); one inside a
/// list by its type alone (no option is a list).
std::string difference(const XmlRpcValue& expected_const, const ParameterValue& actual,
                       const std::string& path) {
  XmlRpcValue expected = expected_const;  // the typed accessors are not const
  const std::string differs = path + ": " + actual.describe() + ", rosparam " + expected.toXml();
  switch (expected.getType()) {
    case XmlRpcValue::TypeBoolean:
      return actual.type == Type::kBool && actual.boolean == static_cast<bool>(expected) ? "" : differs;
    case XmlRpcValue::TypeInt:
      return actual.type == Type::kInt && actual.integer == static_cast<int>(expected) ? "" : differs;
    case XmlRpcValue::TypeString:
      return actual.type == Type::kString && actual.text == static_cast<std::string>(expected) ? "" : differs;
    case XmlRpcValue::TypeDouble: {
      const double a = expected, b = actual.number;
      const bool same = (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof(double)) == 0;
      return actual.type == Type::kDouble && same ? "" : differs;
    }
    case XmlRpcValue::TypeArray:
      if (actual.type != Type::kList || static_cast<int>(actual.items.size()) != expected.size())
        return differs;
      for (int i = 0; i < expected.size(); ++i) {
        const std::string inner =
            difference(expected[i], actual.items[i], path + "[" + std::to_string(i) + "]");
        if (!inner.empty()) return inner;
      }
      return "";
    case XmlRpcValue::TypeStruct:
      return actual.type == Type::kDictionary ? "" : differs;
    default:
      return differs;
  }
}

/// Empty if `actual` holds exactly rosparam's parameters `expected`, else the first difference.
std::string treeDifference(const XmlRpcValue& expected, const hglasm::ParameterTree& actual) {
  const std::vector<std::string> want = XmlRpcParameterSource(expected).leafPaths(), got = actual.leafPaths();
  if (std::set<std::string>(want.begin(), want.end()) != std::set<std::string>(got.begin(), got.end())) {
    return "the parameters' paths differ";
  }
  std::vector<std::pair<std::string, const XmlRpcValue*>> stack = {{"", &expected}};
  while (!stack.empty()) {
    const auto [path, node] = stack.back();
    stack.pop_back();
    for (auto it = node->begin(); it != node->end(); ++it) {
      const std::string child = path.empty() ? it->first : path + "/" + it->first;
      ParameterValue value;
      if (!actual.find(child, &value)) return child + ": missing";
      const std::string inner = difference(it->second, value, child);
      if (!inner.empty()) return inner;
      if (it->second.getType() == XmlRpcValue::TypeStruct) stack.emplace_back(child, &it->second);
    }
  }
  return "";
}

void expectSameAsRosparam(const std::string& path) {
  XmlRpcValue reference;
  hglasm::ParameterTree loaded;
  std::string output, error;
  if (!loadWithRosparam(path, &reference, &output)) GTEST_SKIP() << "rosparam not usable: " << output;
  ASSERT_TRUE(loadYamlParameters(path, &loaded, &error)) << error;
  EXPECT_EQ(treeDifference(reference, loaded), "");
}

TEST(YamlParameters, ShippedConfigurationIsReadAsRosparamReadsIt) {
  expectSameAsRosparam(kSourceDir + "/config/laser_odometry.yaml");
}

TEST(YamlParameters, ShippedPresetsAreReadAsRosparamReadsThem) {
  expectSameAsRosparam(kSourceDir + "/config/presets.yaml");
}

TEST(YamlParameters, EveryKindOfScalarIsTypedAsRosparamTypesIt) {
  expectSameAsRosparam(kSourceDir + "/test/data/yaml_types.yaml");
}

/// The value at `path`, or a kOther value if absent.
ParameterValue at(const hglasm::ParameterSource& source, const std::string& path) {
  ParameterValue value;
  EXPECT_TRUE(source.find(path, &value)) << path;
  return value;
}

TEST(YamlParameters, ShippedConfigurationKeepsIntsBoolsDoublesAndStrings) {
  hglasm::ParameterTree root;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(kSourceDir + "/config/laser_odometry.yaml", &root, &error)) << error;
  EXPECT_EQ(at(root, "queue_size").type, Type::kInt);
  EXPECT_EQ(at(root, "queue_size").integer, 5);
  EXPECT_EQ(at(root, "tf_warn_period").type, Type::kDouble);
  EXPECT_EQ(at(root, "publish_tf").type, Type::kBool);
  EXPECT_EQ(at(root, "preset").text, "medium");
  EXPECT_EQ(at(root, "scan/max_range").type, Type::kDouble);
  EXPECT_TRUE(std::isinf(at(root, "scan/max_range").number));
  EXPECT_EQ(at(root, "odometry/noise/learn").type, Type::kBool);
  EXPECT_EQ(at(root, "odometry/noise").type, Type::kDictionary);
}

TEST(YamlParameters, AnglesOfANumberAreRadians) {
  const std::string path = testing::TempDir() + "hglasm_angles.yaml";
  std::ofstream(path) << "a: deg(80)\nb: deg( -45 )\nc: rad(1.5)\nd: \"deg(80)\"\n";
  hglasm::ParameterTree tree;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(path, &tree, &error)) << error;
  std::remove(path.c_str());
  EXPECT_EQ(at(tree, "a").number, 80.0 * M_PI / 180.0);
  EXPECT_EQ(at(tree, "b").number, -45.0 * M_PI / 180.0);
  EXPECT_EQ(at(tree, "c").number, 1.5);
  EXPECT_EQ(at(tree, "d").type, Type::kString);  // quoted: a string, as rosparam reads it
}

TEST(YamlParameters, ShippedConfigurationLoadsIntoTheNodeletOptions) {
  hglasm::ParameterTree root, presets;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(kSourceDir + "/config/laser_odometry.yaml", &root, &error)) << error;
  ASSERT_TRUE(loadYamlParameters(kSourceDir + "/config/presets.yaml", &presets, &error)) << error;
  root.setTree("presets", presets);
  LaserOdometryOptions options;
  std::vector<std::string> warnings;
  ASSERT_TRUE(loadOptions(root, &options, &error, &warnings)) << error;
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_EQ(options.preset, "medium");
}

TEST(YamlParameters, AnOptionsTypeErrorNamesTheParameterAsTheNodeletDoes) {
  const std::string path = testing::TempDir() + "hglasm_wrong_type.yaml";
  std::ofstream(path) << "genetic:\n  population: deg(80)\n";
  hglasm::ParameterTree root;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(path, &root, &error)) << error;
  std::remove(path.c_str());
  LaserOdometryOptions options;
  EXPECT_FALSE(loadOptions(root, &options, &error));
  EXPECT_EQ(error, "parameter ~genetic/population must be an integer in [2, 100000], got 1.39626");
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

std::string loadError(const std::string& name, const std::string& text) {
  const std::string path = writeFile(name, text);
  hglasm::ParameterTree value;
  std::string error;
  EXPECT_FALSE(loadYamlParameters(path, &value, &error));
  std::remove(path.c_str());
  return error;
}

TEST(YamlParameters, InvalidYamlIsAnErrorNamingFileLineAndColumn) {
  const std::string error = loadError("hglasm_invalid.yaml", "a: 1\nb: [1, 2\nc: 3\n");
  EXPECT_NE(error.find("hglasm_invalid.yaml:"), std::string::npos) << error;
  EXPECT_NE(error.find("end of sequence flow not found"), std::string::npos) << error;
}

TEST(YamlParameters, ErrorsNameTheFileTheLineAndTheKey) {
  EXPECT_NE(loadError("hglasm_null.yaml", "a: 1\nb: ~\n").find("hglasm_null.yaml:2: b: a null value"),
            std::string::npos);
  const std::string nested = loadError("hglasm_nested.yaml", "outer:\n  list: [1, 2]\n  inner: 1e-3\n");
  EXPECT_NE(nested.find("hglasm_nested.yaml:3: outer/inner: '1e-3' is not read here as rosparam reads it"),
            std::string::npos)
      << nested;
  const std::string listed = loadError("hglasm_listed.yaml", "outer:\n  list: [1, ~]\n");
  EXPECT_NE(listed.find(":2: outer/list[1]: a null value"), std::string::npos) << listed;
}

TEST(YamlParameters, WhatTheParameterServerCannotHoldIsAnError) {
  EXPECT_NE(loadError("hglasm_key.yaml", "1: one\n").find("1: a key must be a string"), std::string::npos);
  EXPECT_NE(loadError("hglasm_big.yaml", "a: 4294967296\n").find("not a 32-bit int"), std::string::npos);
  EXPECT_NE(loadError("hglasm_list.yaml", "- 1\n- 2\n").find("does not hold a dictionary"),
            std::string::npos);
  EXPECT_NE(loadError("hglasm_tag.yaml", "a: !custom 1\n").find("unsupported tag '!custom'"),
            std::string::npos);
  EXPECT_NE(loadError("hglasm_str.yaml", "a: !!str 12\n").find("unsupported tag"), std::string::npos);
}

TEST(YamlParameters, ScalarsRosparamWouldReadOtherwiseAreErrors) {
  // rosparam: a string, 8, 31, 5, 90, 1000, a string, a date, a merge, an expression, an expression.
  for (const char* text :
       {"1e-3", "010", "0x1F", "0b101", "1:30", "1_000", "-.5", "2024-01-02", "deg(pi)", "rad(pi/2)", "08"}) {
    const std::string error = loadError("hglasm_refused.yaml", std::string("a: ") + text + "\n");
    EXPECT_NE(error.find(std::string("a: '") + text + "' is not read here"), std::string::npos) << error;
  }
  const std::string merge = loadError("hglasm_merge.yaml", "base: &b {x: 1}\nm:\n  <<: *b\n");
  EXPECT_NE(merge.find(":3: m/<<: '<<' is not read here"), std::string::npos) << merge;
}

TEST(YamlParameters, MissingFileIsAnError) {
  hglasm::ParameterTree value;
  std::string error;
  EXPECT_FALSE(loadYamlParameters("/nonexistent/params.yaml", &value, &error));
  EXPECT_EQ(error, "cannot read /nonexistent/params.yaml");
}

TEST(YamlParameters, EmptyFileHoldsNoParameters) {
  const std::string path = writeFile("hglasm_empty.yaml", "# only a comment\n");
  hglasm::ParameterTree value;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(path, &value, &error)) << error;
  std::remove(path.c_str());
  EXPECT_TRUE(value.values().empty());
}

}  // namespace
}  // namespace hglasm_odometry
