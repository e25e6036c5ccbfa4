// loadYamlParameters gives exactly what rosparam gives (the same types, the same bits) on the shipped
// configuration and on a file of every kind of scalar it reads, and an error naming the key on what it
// refuses (what rosparam would read otherwise or the parameter server cannot hold).
#include "hglasm_odometry/tools/yaml_parameters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "hglasm_odometry/ros/parameters.h"

namespace hglasm_odometry {
namespace {

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

/// Empty if equal in type and value (doubles bit for bit, NaN equal to NaN), else the first difference.
std::string difference(const XmlRpcValue& expected_const, const XmlRpcValue& actual_const,
                       const std::string& path) {
  XmlRpcValue expected = expected_const, actual = actual_const;  // the typed accessors are not const
  if (expected.getType() != actual.getType()) {
    return path + ": type " + std::to_string(actual.getType()) + ", rosparam " +
           std::to_string(expected.getType()) + " (" + expected.toXml() + " vs " + actual.toXml() + ")";
  }
  switch (expected.getType()) {
    case XmlRpcValue::TypeDouble: {
      const double a = expected, b = actual;
      const bool same = (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof(double)) == 0;
      return same ? "" : path + ": " + actual.toXml() + ", rosparam " + expected.toXml();
    }
    case XmlRpcValue::TypeArray:
      if (expected.size() != actual.size()) return path + ": list sizes differ";
      for (int i = 0; i < expected.size(); ++i) {
        const std::string inner = difference(expected[i], actual[i], path + "[" + std::to_string(i) + "]");
        if (!inner.empty()) return inner;
      }
      return "";
    case XmlRpcValue::TypeStruct:
      if (expected.size() != actual.size()) return path + ": mapping sizes differ";
      for (auto& entry : expected) {
        if (!actual.hasMember(entry.first)) return path + "/" + entry.first + ": missing";
        const std::string inner = difference(entry.second, actual[entry.first], path + "/" + entry.first);
        if (!inner.empty()) return inner;
      }
      return "";
    default:
      return expected == actual ? "" : path + ": " + actual.toXml() + ", rosparam " + expected.toXml();
  }
}

void expectSameAsRosparam(const std::string& path) {
  XmlRpcValue reference, loaded;
  std::string output, error;
  if (!loadWithRosparam(path, &reference, &output)) GTEST_SKIP() << "rosparam not usable: " << output;
  ASSERT_TRUE(loadYamlParameters(path, &loaded, &error)) << error;
  EXPECT_EQ(difference(reference, loaded, path), "");
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

TEST(YamlParameters, ShippedConfigurationKeepsIntsBoolsDoublesAndStrings) {
  XmlRpcValue root;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(kSourceDir + "/config/laser_odometry.yaml", &root, &error)) << error;
  EXPECT_EQ(root["queue_size"].getType(), XmlRpcValue::TypeInt);
  EXPECT_EQ(static_cast<int>(root["queue_size"]), 5);
  EXPECT_EQ(root["tf_warn_period"].getType(), XmlRpcValue::TypeDouble);
  EXPECT_EQ(root["publish_tf"].getType(), XmlRpcValue::TypeBoolean);
  EXPECT_EQ(static_cast<std::string>(root["preset"]), "medium");
  EXPECT_EQ(root["scan"]["max_range"].getType(), XmlRpcValue::TypeDouble);
  EXPECT_TRUE(std::isinf(static_cast<double>(root["scan"]["max_range"])));
  EXPECT_EQ(root["odometry"]["noise"]["learn"].getType(), XmlRpcValue::TypeBoolean);

  XmlRpcValue presets;
  ASSERT_TRUE(loadYamlParameters(kSourceDir + "/config/presets.yaml", &presets, &error)) << error;
  EXPECT_EQ(static_cast<double>(presets["medium"]["mbicp"]["degenerate_eigenvalue"]), 1.0e-06);
  EXPECT_EQ(presets["medium"]["genetic"]["population"].getType(), XmlRpcValue::TypeInt);
}

TEST(YamlParameters, ShippedConfigurationLoadsIntoTheNodeletOptions) {
  XmlRpcValue root, presets;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(kSourceDir + "/config/laser_odometry.yaml", &root, &error)) << error;
  ASSERT_TRUE(loadYamlParameters(kSourceDir + "/config/presets.yaml", &presets, &error)) << error;
  root["presets"] = presets;
  LaserOdometryOptions options;
  std::vector<std::string> warnings;
  ASSERT_TRUE(loadOptions(root, &options, &error, &warnings)) << error;
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_EQ(options.preset, "medium");
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

std::string loadError(const std::string& name, const std::string& text) {
  const std::string path = writeFile(name, text);
  XmlRpcValue value;
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
  XmlRpcValue value;
  std::string error;
  EXPECT_FALSE(loadYamlParameters("/nonexistent/params.yaml", &value, &error));
  EXPECT_EQ(error, "cannot read /nonexistent/params.yaml");
}

TEST(YamlParameters, EmptyFileHoldsNoParameters) {
  const std::string path = writeFile("hglasm_empty.yaml", "# only a comment\n");
  XmlRpcValue value;
  std::string error;
  ASSERT_TRUE(loadYamlParameters(path, &value, &error)) << error;
  std::remove(path.c_str());
  EXPECT_EQ(value.getType(), XmlRpcValue::TypeStruct);
  EXPECT_EQ(value.size(), 0);
}

}  // namespace
}  // namespace hglasm_odometry
