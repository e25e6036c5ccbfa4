// evaluate's set-up: its command line, the nodelet's options from the shipped YAML (and what happens when a
// file is missing), and the bag with the command line's overrides.
#include "hglasm_odometry/tools/evaluate_setup.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace hglasm_odometry {
namespace {

const std::string kSource = HGLASM_SOURCE_DIR;
const std::string kBag = kSource + "/bags/fr079_slice.bag";

ArgumentParser::Result parse(const std::vector<std::string>& arguments, EvaluateArguments* args) {
  return parseEvaluateArguments(arguments, args);
}

TEST(EvaluateSetup, ParsesTheCommandLine) {
  EvaluateArguments args;
  ASSERT_EQ(parse({"--bag", "b.bag", "--no-odom", "--laser-mount", "0.1,-0.2,0.3", "--max-scans", "7",
                   "--angle-min", "-1.5", "--preset", "small", "--max-span", "5", "--blend-wheels",
                   "--relations", "r.relations", "--relation-errors", "e.txt"},
                  &args),
            ArgumentParser::Result::kOk);
  EXPECT_EQ(args.bag, "b.bag");
  EXPECT_FALSE(args.use_odometry);
  EXPECT_TRUE(args.override_mount);
  EXPECT_DOUBLE_EQ(args.laser_mount.y, -0.2);
  EXPECT_EQ(args.max_scans, 7u);
  EXPECT_TRUE(args.beam_angles.angle_min_given);
  EXPECT_FALSE(args.beam_angles.angle_increment_given);
  EXPECT_EQ(args.preset, "small");
  EXPECT_EQ(args.short_span, 5.0);
  EXPECT_TRUE(args.blend_wheels);
  EXPECT_EQ(args.relation_errors, "e.txt");
  EXPECT_FALSE(args.direct_pairs);
  EXPECT_FALSE(args.config_given);
  EXPECT_EQ(args.pace_rate, 0.0);
  EvaluateArguments paced;
  ASSERT_EQ(parse({"--bag", "b.bag", "--pace", "3"}, &paced), ArgumentParser::Result::kOk);
  EXPECT_EQ(paced.pace_rate, 3.0);
}

TEST(EvaluateSetup, RefusesAMissingBagAndABadMount) {
  EvaluateArguments args;
  EXPECT_EQ(parse({"--out", "x.txt"}, &args), ArgumentParser::Result::kError);
  EvaluateArguments errors_alone;
  EXPECT_EQ(parse({"--bag", "b.bag", "--relation-errors", "e.txt"}, &errors_alone),
            ArgumentParser::Result::kError);
  EvaluateArguments pace;
  EXPECT_EQ(parse({"--bag", "b.bag", "--pace", "-1"}, &pace), ArgumentParser::Result::kError);
  EvaluateArguments crawl;
  EXPECT_EQ(parse({"--bag", "b.bag", "--pace", "1e-12"}, &crawl), ArgumentParser::Result::kError);
  EvaluateArguments mount;
  EXPECT_EQ(parse({"--bag", "b.bag", "--laser-mount", "0.1,0.2"}, &mount), ArgumentParser::Result::kError);
  hglasm::Pose2D pose;
  std::string error;
  EXPECT_FALSE(parseLaserMount("1,2,nan", &pose, &error));
  EXPECT_EQ(error, "expects X,Y,YAW, got '1,2,nan'");
}

TEST(EvaluateSetup, PresetsAreNextToTheConfig) {
  EXPECT_EQ(presetsNextTo("/a/b/laser_odometry.yaml"), "/a/b/presets.yaml");
  EXPECT_EQ(presetsNextTo("mine.yaml"), "presets.yaml");
}

/// What loadEvaluateOptions gives for `args`.
struct Loaded {
  bool ok = false;
  LaserOdometryOptions options;
  std::vector<std::string> warnings;
  bool config_found = false;
  std::string error;
};

Loaded load(const EvaluateArguments& args) {
  Loaded loaded;
  loaded.ok =
      loadEvaluateOptions(args, &loaded.options, &loaded.warnings, &loaded.config_found, &loaded.error);
  return loaded;
}

TEST(EvaluateSetup, LoadsTheShippedConfigurationAndThePresetAsked) {
  EvaluateArguments args;
  args.config = kSource + "/config/laser_odometry.yaml";
  args.config_given = true;
  const Loaded shipped = load(args);
  ASSERT_TRUE(shipped.ok) << shipped.error;
  EXPECT_TRUE(shipped.config_found);
  EXPECT_TRUE(shipped.warnings.empty());
  EXPECT_EQ(shipped.options.preset, "medium");
  args.preset = "small";
  const Loaded small = load(args);
  ASSERT_TRUE(small.ok) << small.error;
  EXPECT_EQ(small.options.preset, "small");
  EXPECT_LT(small.options.tracker.matcher.genetic.population,
            shipped.options.tracker.matcher.genetic.population);
}

TEST(EvaluateSetup, AMissingDefaultMeansDefaultsAMissingGivenFileAnError) {
  EvaluateArguments args;
  args.config = "/nonexistent/laser_odometry.yaml";
  const Loaded defaults = load(args);
  ASSERT_TRUE(defaults.ok) << defaults.error;
  EXPECT_FALSE(defaults.config_found);
  args.config_given = true;
  const Loaded missing = load(args);
  EXPECT_FALSE(missing.ok);
  EXPECT_EQ(missing.error, "cannot read /nonexistent/laser_odometry.yaml");
}

TEST(EvaluateSetup, PresetsMayBeNestedUnderAPresetsKey) {
  const std::string presets = testing::TempDir() + "hglasm_nested_presets.yaml";
  std::ofstream(presets) << "presets:\n  tiny:\n    genetic:\n      population: 12\n";
  EvaluateArguments args;
  args.config = "/nonexistent/laser_odometry.yaml";
  args.presets = presets;
  args.presets_given = true;
  args.preset = "tiny";
  const Loaded tiny = load(args);
  ASSERT_TRUE(tiny.ok) << tiny.error;
  EXPECT_EQ(tiny.options.preset, "tiny");
  EXPECT_EQ(tiny.options.tracker.matcher.genetic.population, 12);
  std::remove(presets.c_str());
}

TEST(EvaluateSetup, InputsCarryTheOverrides) {
  EvaluateArguments args;
  args.bag = kBag;
  args.relations = kSource + "/bags/fr079_slice.relations";
  args.max_scans = 20;
  EvaluateInputs plain;
  std::string error;
  ASSERT_TRUE(readEvaluateInputs(args, "", &plain, &error)) << error;
  EXPECT_EQ(plain.data.scans.size(), 20u);
  EXPECT_EQ(plain.relations.size(), 156u);
  EXPECT_EQ(plain.mount_source, "from tf");

  args.override_mount = true;
  args.laser_mount = hglasm::Pose2D(0.3, 0.0, 0.1);
  args.beam_angles.angle_increment_given = true;
  args.beam_angles.angle_increment = 0.02;
  args.odom_stamp_shift = 0.5;
  EvaluateInputs changed;
  ASSERT_TRUE(readEvaluateInputs(args, "", &changed, &error)) << error;
  EXPECT_EQ(changed.mount_source, "from --laser-mount");
  EXPECT_EQ(changed.data.base_to_laser.x, 0.3);
  for (const BagScan& scan : changed.data.scans) EXPECT_EQ(scan.ranges.angle_increment, 0.02);
  ASSERT_EQ(changed.data.odometry.size(), plain.data.odometry.size());
  EXPECT_NEAR(changed.data.odometry.front().stamp - plain.data.odometry.front().stamp, 0.5, 1e-9);

  args.bag = "/nonexistent.bag";
  EXPECT_FALSE(readEvaluateInputs(args, "", &changed, &error));
}

}  // namespace
}  // namespace hglasm_odometry
