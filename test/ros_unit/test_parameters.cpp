// Parameter loading and validation from XmlRpc values (as the parameter server returns them): no master.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/ros/parameters.h"

namespace hglasm_odometry {
namespace {

using XmlRpc::XmlRpcValue;

/// Sets root["a"]["b"]... = value for a path "a/b".
void set(XmlRpcValue& root, const std::string& path, const XmlRpcValue& value) {
  XmlRpcValue* node = &root;
  std::size_t start = 0;
  while (true) {
    const std::size_t slash = path.find('/', start);
    const std::string key =
        path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (slash == std::string::npos) {
      (*node)[key] = value;
      return;
    }
    node = &(*node)[key];
    start = slash + 1;
  }
}

XmlRpcValue params(std::initializer_list<std::pair<std::string, XmlRpcValue>> entries) {
  XmlRpcValue root;
  for (const auto& entry : entries) set(root, entry.first, entry.second);
  return root;
}

/// Loads and expects failure; returns the error.
std::string loadError(const XmlRpcValue& root) {
  LaserOdometryOptions options;
  std::string error;
  EXPECT_FALSE(loadOptions(root, &options, &error));
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find('\n'), std::string::npos) << "one line: " << error;
  return error;
}

TEST(Parameters, NoParametersGiveTheMediumPresetAndDefaults) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(XmlRpcValue(), &options, &error)) << error;
  EXPECT_EQ(options.preset, "medium");
  const hglasm::MatcherOptions medium = hglasm::presetOptions(hglasm::Preset::kMedium);
  EXPECT_EQ(options.tracker.matcher.genetic.population, medium.genetic.population);
  EXPECT_EQ(options.tracker.matcher.genetic.box.half_theta, medium.genetic.box.half_theta);
  EXPECT_EQ(options.odom_frame, "odom");
  EXPECT_EQ(options.base_frame, "base_link");
  EXPECT_TRUE(options.publish_tf);
  EXPECT_TRUE(options.tracker.prediction.use_odometry);
  EXPECT_FALSE(options.publish_population);
  EXPECT_GE(options.queue_size, 1);
  EXPECT_FALSE(options.set_pose.topic_enabled) << "the set-pose topic is off by default";
  EXPECT_EQ(options.set_pose.topic, "set_pose");
}

TEST(Parameters, BuiltInPresetsSelectTheirSearchSpace) {
  for (const char* name : {"small", "medium", "large"}) {
    LaserOdometryOptions options;
    std::string error;
    ASSERT_TRUE(loadOptions(params({{"preset", name}}), &options, &error)) << error;
    hglasm::Preset preset;
    ASSERT_TRUE(hglasm::parsePreset(name, &preset));
    const hglasm::MatcherOptions expected = hglasm::presetOptions(preset);
    EXPECT_EQ(options.preset, name);
    EXPECT_EQ(options.tracker.matcher.genetic.population, expected.genetic.population) << name;
    EXPECT_EQ(options.tracker.matcher.genetic.generations, expected.genetic.generations) << name;
    EXPECT_EQ(options.tracker.matcher.genetic.runs, expected.genetic.runs) << name;
    EXPECT_DOUBLE_EQ(options.tracker.matcher.genetic.box.half_x, expected.genetic.box.half_x) << name;
  }
}

TEST(Parameters, PresetsYamlThenTopLevelOverridesWin) {
  XmlRpcValue root = params({{"preset", "small"},
                             {"presets/small/genetic/population", 33},
                             {"presets/small/genetic/box_x", 0.4},
                             {"presets/large/genetic/population", 999},
                             {"genetic/box_x", 0.5},
                             {"keyframe/distance", 0.7},
                             {"odom_frame", "/laser_odom"},
                             {"use_odom", false}});
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(root, &options, &error)) << error;
  EXPECT_EQ(options.tracker.matcher.genetic.population, 33);          // from ~presets/small
  EXPECT_DOUBLE_EQ(options.tracker.matcher.genetic.box.half_x, 0.5);  // top level beats the preset
  EXPECT_DOUBLE_EQ(options.tracker.keyframe.distance, 0.7);
  EXPECT_EQ(options.odom_frame, "laser_odom");  // leading slash stripped
  EXPECT_FALSE(options.tracker.prediction.use_odometry);
}

TEST(Parameters, IntegersAreAcceptedWhereNumbersAreExpected) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({{"genetic/box_theta", 1}, {"scan/max_range", 20}}), &options, &error))
      << error;
  EXPECT_DOUBLE_EQ(options.tracker.matcher.genetic.box.half_theta, 1.0);
  EXPECT_DOUBLE_EQ(options.tracker.conversion.max_range, 20.0);
}

TEST(Parameters, CustomPresetDefinedUnderPresetsIsAccepted) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({{"preset", "corridor"}, {"presets/corridor/genetic/box_x", 1.5}}), &options,
                          &error))
      << error;
  EXPECT_EQ(options.preset, "corridor");
  EXPECT_DOUBLE_EQ(options.tracker.matcher.genetic.box.half_x, 1.5);
}

TEST(Parameters, UnknownPresetNamesTheParameter) {
  const std::string error = loadError(params({{"preset", "huge"}}));
  EXPECT_NE(error.find("~preset"), std::string::npos) << error;
  EXPECT_NE(error.find("huge"), std::string::npos) << error;
  EXPECT_NE(error.find("small"), std::string::npos) << error;
}

TEST(Parameters, NegativeAndZeroSizesNameTheParameter) {
  EXPECT_EQ(loadError(params({{"genetic/population", -5}})),
            "parameter ~genetic/population must be an integer in [2, 100000], got -5");
  EXPECT_NE(loadError(params({{"genetic/generations", 0}}))
                .find("~genetic/generations must be a positive integer, got 0"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"queue_size", 0}})).find("~queue_size"), std::string::npos);
  EXPECT_NE(loadError(params({{"path_length", -1}})).find("~path_length"), std::string::npos);
  EXPECT_NE(
      loadError(params({{"table/cell_size", 0.0}})).find("~table/cell_size must be a positive number, got 0"),
      std::string::npos);
  EXPECT_NE(loadError(params({{"genetic/box_x", -0.3}})).find("~genetic/box_x"), std::string::npos);
  EXPECT_NE(loadError(params({{"mbicp/max_iterations", -1}})).find("~mbicp/max_iterations"),
            std::string::npos);
}

TEST(Parameters, OutOfRangeValuesNameTheParameter) {
  EXPECT_NE(loadError(params({{"genetic/crossover_rate", 1.5}}))
                .find("~genetic/crossover_rate must be a number in [0, 1]"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"genetic/box_theta", 4.0}})).find("~genetic/box_theta"), std::string::npos);
  EXPECT_NE(loadError(params({{"min_fitness", -0.1}})).find("~min_fitness"), std::string::npos);
  EXPECT_NE(loadError(params({{"genetic/bits_per_gene", 40}})).find("~genetic/bits_per_gene"),
            std::string::npos);
  // The GA keeps at least its best individual: 0 elites is refused, not quietly made 1.
  EXPECT_EQ(loadError(params({{"genetic/elite_count", 0}})),
            "parameter ~genetic/elite_count must be an integer in [1, 100000], got 0");
  EXPECT_EQ(loadError(params({{"presets/medium/genetic/elite_count", 0}})),
            "parameter ~presets/medium/genetic/elite_count must be an integer in [1, 100000], got 0");
  EXPECT_NE(loadError(params({{"genetic/tournament_size", 30}, {"genetic/population", 20}}))
                .find("~genetic/tournament_size"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"scan/min_range", 5.0}, {"scan/max_range", 2.0}})).find("~scan/max_range"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"odom_frame", "base_link"}})).find("~base_frame"), std::string::npos);
  EXPECT_NE(
      loadError(params({{"scan/sweep_time", -0.01}})).find("~scan/sweep_time must be a number in [0, 1]"),
      std::string::npos);
  EXPECT_NE(loadError(params({{"scan/deskew", 1.5}})).find("~scan/deskew"), std::string::npos);
}

TEST(Parameters, FusionLocalMapAndNoiseParametersAreValidated) {
  EXPECT_NE(
      loadError(params({{"leap/probability", 0.0}})).find("~leap/probability must be a number in [0, 0.5]"),
      std::string::npos);
  EXPECT_NE(loadError(params({{"leap/persistence", 1.5}})).find("~leap/persistence"), std::string::npos);
  EXPECT_NE(
      loadError(params({{"leap/max_mahalanobis", 0.0}})).find("~leap/max_mahalanobis must be a positive"),
      std::string::npos);
  EXPECT_NE(
      loadError(params({{"local_map/keyframes", 0}})).find("~local_map/keyframes must be a positive integer"),
      std::string::npos);
  EXPECT_NE(loadError(params({{"local_map/resolution", -0.1}})).find("~local_map/resolution"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"search/sigmas", -1.0}})).find("~search/sigmas"), std::string::npos);
  EXPECT_NE(loadError(params({{"odometry/noise/xy_per_metre", -0.1}})).find("~odometry/noise/xy_per_metre"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"odometry/noise/min_scale", 2.0}, {"odometry/noise/max_scale", 1.0}}))
                .find("~odometry/noise/max_scale must be at least ~odometry/noise/min_scale"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"scan_noise/min_scale", 2.0}, {"scan_noise/max_scale", 1.0}}))
                .find("~scan_noise/max_scale must be at least ~scan_noise/min_scale"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"covariance/unexplained_xy", "big"}})).find("~covariance/unexplained_xy"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"fusion", 1}})).find("~fusion must be true or false"), std::string::npos);
  EXPECT_NE(loadError(params({{"mbicp/independent_points", -5.0}})).find("~mbicp/independent_points"),
            std::string::npos);
}

TEST(Parameters, FusionLocalMapAndNoiseParametersAreRead) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({{"fusion", false},
                                  {"local_map/keyframes", 3},
                                  {"local_map/resolution", 0.05},
                                  {"leap/probability", 0.01},
                                  {"odometry/noise/learn", false},
                                  {"odometry/noise/learn_lags", 3},
                                  {"odometry/noise/systematic", 0.02},
                                  {"odometry/calibration/learn", false},
                                  {"odometry/calibration/turn_scale", 0.2},
                                  {"odometry/calibration/heading_per_metre", 0.01},
                                  {"odometry/calibration/laser_offset", 0.05},
                                  {"scan_noise/learn", true},
                                  {"scan_noise/directional", false},
                                  {"scan_noise/min_scale", 0.5},
                                  {"odometry/noise/theta_per_radian", 0.2},
                                  {"constant_velocity/xy", 2.0},
                                  {"covariance/unexplained_theta", 0.01},
                                  {"search/min_xy", 0.2}}),
                          &options, &error))
      << error;
  const hglasm::TrackerOptions& t = options.tracker;
  EXPECT_FALSE(t.fusion);
  EXPECT_EQ(t.local_map.keyframes, 3);
  EXPECT_EQ(t.local_map.resolution, 0.05);
  EXPECT_EQ(t.leap.probability, 0.01);
  EXPECT_FALSE(t.learning.noise.learn_wheels);
  EXPECT_EQ(t.learning.noise.lags, 3);
  EXPECT_EQ(t.motion.systematic, 0.02);
  EXPECT_FALSE(t.learning.wheel_calibration.learn);
  EXPECT_EQ(t.learning.wheel_calibration.turn_scale, 0.2);
  EXPECT_EQ(t.learning.wheel_calibration.heading_per_metre, 0.01);
  EXPECT_EQ(t.learning.wheel_calibration.laser_offset, 0.05);
  EXPECT_TRUE(t.learning.noise.learn_scan);
  EXPECT_FALSE(t.learning.noise.directional);
  EXPECT_EQ(t.learning.noise.min_scan_scale, 0.5);
  EXPECT_EQ(t.motion.theta_per_radian, 0.2);
  EXPECT_EQ(t.motion.constant_velocity_xy, 2.0);
  EXPECT_EQ(t.uncertainty.unexplained_theta, 0.01);
  EXPECT_EQ(t.search.min_xy, 0.2);
}

TEST(Parameters, NonFiniteNumbersAreRejectedExceptAnInfiniteMaxRange) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(loadError(params({{"keyframe/distance", nan}})).find("~keyframe/distance"), std::string::npos);
  EXPECT_NE(loadError(params({{"genetic/box_y", inf}})).find("~genetic/box_y"), std::string::npos);
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({{"scan/max_range", inf}}), &options, &error)) << error;
  EXPECT_TRUE(std::isinf(options.tracker.conversion.max_range));
}

TEST(Parameters, WrongTypesNameTheParameterAndTheValue) {
  EXPECT_EQ(loadError(params({{"genetic/population", "lots"}})),
            "parameter ~genetic/population must be an integer in [2, 100000], got string \"lots\"");
  EXPECT_NE(loadError(params({{"genetic/population", 20.5}})).find("~genetic/population"), std::string::npos);
  EXPECT_EQ(loadError(params({{"publish_tf", "yes"}})),
            "parameter ~publish_tf must be true or false, got string \"yes\"");
  EXPECT_NE(
      loadError(params({{"keyframe/distance", "far"}})).find("~keyframe/distance must be a positive number"),
      std::string::npos);
  EXPECT_NE(loadError(params({{"preset", 3}})).find("~preset must be a non-empty string, got 3"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"base_frame", true}})).find("~base_frame"), std::string::npos);
  XmlRpcValue list;
  list[0] = 1;
  list[1] = 2;
  EXPECT_NE(loadError(params({{"keyframe/angle", list}})).find("got a list"), std::string::npos);
  EXPECT_NE(loadError(params({{"presets", 5}})).find("~presets"), std::string::npos);
  EXPECT_NE(loadError(params({{"preset", "small"}, {"presets/small", "big"}})).find("~presets/small"),
            std::string::npos);
}

TEST(Parameters, ErrorsInsideThePresetsFileNameTheFullPath) {
  const std::string error =
      loadError(params({{"preset", "large"}, {"presets/large/genetic/population", -5}}));
  EXPECT_NE(error.find("~presets/large/genetic/population"), std::string::npos) << error;
  // A broken preset that is not selected does not matter.
  LaserOdometryOptions options;
  std::string load_error;
  EXPECT_TRUE(loadOptions(params({{"preset", "small"}, {"presets/large/genetic/population", -5}}), &options,
                          &load_error))
      << load_error;
}

TEST(Parameters, UnknownKeysAreWarningsNotErrors) {
  LaserOdometryOptions options;
  std::string error;
  std::vector<std::string> warnings;
  ASSERT_TRUE(loadOptions(params({{"genetic/populaton", 30},
                                  {"publish_tf", true},
                                  {"diagnostic_period", 1.0},
                                  {"presets/medium/genetic/generatons", 3}}),
                          &options, &error, &warnings))
      << error;
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("~presets/medium/genetic/generatons"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("~genetic/populaton"), std::string::npos) << warnings[1];
}

TEST(Parameters, TheTimePolicyAndTheWheelsTimeOffsetAreReadAndValidated) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(XmlRpcValue(), &options, &error)) << error;
  EXPECT_TRUE(options.tracker.learning.odometry_time_offset.estimate) << "auto by default";
  EXPECT_EQ(options.tracker.learning.odometry_time_offset.max_offset, 1.0);
  EXPECT_EQ(options.tracker.reset_on_jump_back, 3.0);
  ASSERT_TRUE(loadOptions(params({{"odometry/time_offset", "auto"}, {"odometry/max_time_offset", 2.0}}),
                          &options, &error))
      << error;
  EXPECT_TRUE(options.tracker.learning.odometry_time_offset.estimate);
  EXPECT_EQ(options.tracker.learning.odometry_time_offset.max_offset, 2.0);
  ASSERT_TRUE(
      loadOptions(params({{"odometry/time_offset", 0.3}, {"time/reset_on_jump_back", 10}}), &options, &error))
      << error;
  EXPECT_FALSE(options.tracker.learning.odometry_time_offset.estimate) << "a number fixes it";
  EXPECT_EQ(options.tracker.learning.odometry_time_offset.offset, 0.3);
  EXPECT_EQ(options.tracker.reset_on_jump_back, 10.0);
  ASSERT_TRUE(loadOptions(params({{"odometry/time_offset", -1}}), &options, &error)) << error;
  EXPECT_EQ(options.tracker.learning.odometry_time_offset.offset, -1.0);
  for (const XmlRpcValue& bad : {XmlRpcValue("automatic"), XmlRpcValue(11.0), XmlRpcValue(true)}) {
    const std::string error_text = loadError(params({{"odometry/time_offset", bad}}));
    EXPECT_NE(error_text.find("~odometry/time_offset must be auto or a number of seconds"), std::string::npos)
        << error_text;
  }
  EXPECT_NE(loadError(params({{"time/reset_on_jump_back", 0.0}})).find("~time/reset_on_jump_back"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"odometry/max_time_offset", -0.5}})).find("~odometry/max_time_offset"),
            std::string::npos);
}

TEST(Parameters, TheRetiredMaxTimeJumpSaysWhatReplacedIt) {
  LaserOdometryOptions options;
  std::string error;
  std::vector<std::string> warnings;
  ASSERT_TRUE(loadOptions(params({{"max_time_jump", 60.0}}), &options, &error, &warnings)) << error;
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("~max_time_jump is no longer used"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("~time/reset_on_jump_back"), std::string::npos) << warnings[0];
}

TEST(Parameters, TheRemovedAlgorithmIsAnErrorThatSaysSo) {
  // Any value, the odometry's own included: the setting no longer chooses anything.
  for (const char* value : {"pga", "hglasm_g"}) {
    const std::string error = loadError(params({{"algorithm", value}}));
    EXPECT_EQ(error.find("parameter ~algorithm (string \"" + std::string(value) + "\") was removed"), 0u)
        << error;
    EXPECT_NE(error.find("success_ratio"), std::string::npos) << error;
  }
  const std::string in_preset =
      loadError(params({{"preset", "small"}, {"presets/small/algorithm", "mbicp"}}));
  EXPECT_EQ(in_preset.find("parameter ~presets/small/algorithm (string \"mbicp\") was removed"), 0u)
      << in_preset;
}

TEST(Parameters, ToParamsIsWhatLoadOptionsReadsBack) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({{"preset", "large"},
                                  {"genetic/elite_count", 2},
                                  {"genetic/seed", 77},
                                  {"mbicp/point_to_line", false},
                                  {"scan/max_range", 12.5},
                                  {"use_odom", false},
                                  {"odometry/time_offset", 0.2},
                                  {"base_frame", "/base"}}),
                          &options, &error))
      << error;
  XmlRpcValue written = toParams(options);
  EXPECT_FALSE(written.hasMember("algorithm"));
  EXPECT_EQ(static_cast<int>(written["genetic"]["elite_count"]), 2);
  EXPECT_EQ(static_cast<bool>(written["use_odom"]), false);
  EXPECT_EQ(static_cast<std::string>(written["base_frame"]), "base");
  EXPECT_EQ(static_cast<double>(written["odometry"]["time_offset"]), 0.2);
  std::vector<std::string> warnings;
  LaserOdometryOptions again;
  ASSERT_TRUE(loadOptions(written, &again, &error, &warnings)) << error;
  EXPECT_TRUE(warnings.empty());
  EXPECT_TRUE(toParams(again) == written);
  EXPECT_EQ(again.tracker.matcher.genetic.seed, 77u);
  EXPECT_DOUBLE_EQ(again.tracker.matcher.genetic.box.half_theta, M_PI);  // large's, written out
}

TEST(Parameters, SummaryMentionsThePresetAndFrames) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({{"preset", "large"}}), &options, &error));
  const std::string summary = summarize(options);
  EXPECT_NE(summary.find("large"), std::string::npos);
  EXPECT_NE(summary.find("odom -> base_link"), std::string::npos);
}

TEST(Parameters, SetPoseTopicIsReadAndValidated) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({{"set_pose/topic_enabled", true}, {"set_pose/topic", "/initialpose"}}),
                          &options, &error))
      << error;
  EXPECT_TRUE(options.set_pose.topic_enabled);
  EXPECT_EQ(options.set_pose.topic, "/initialpose");
  EXPECT_EQ(loadError(params({{"set_pose/topic_enabled", "yes"}})),
            "parameter ~set_pose/topic_enabled must be true or false, got string \"yes\"");
  EXPECT_EQ(loadError(params({{"set_pose/topic", "2d pose"}})),
            "parameter ~set_pose/topic must be a relative or absolute topic name, got string \"2d pose\"");
  EXPECT_NE(loadError(params({{"set_pose/topic", "~initialpose"}})).find("~set_pose/topic"),
            std::string::npos);
  EXPECT_NE(loadError(params({{"set_pose/topic", ""}})).find("~set_pose/topic must be a non-empty string"),
            std::string::npos);
}

TEST(Parameters, ImuParametersAreReadAndValidated) {
  LaserOdometryOptions options;
  std::string error;
  ASSERT_TRUE(loadOptions(params({}), &options, &error)) << error;
  EXPECT_FALSE(options.tracker.prediction.use_imu) << "off by default";
  ASSERT_TRUE(loadOptions(params({{"use_imu", true},
                                  {"imu/use_orientation", true},
                                  {"imu/max_gap", 0.05},
                                  {"imu/noise/angle_random_walk", 0.001},
                                  {"imu/noise/bias_sigma", 0},
                                  {"imu/noise/scale_error", 0.05},
                                  {"imu/noise/estimate_bias", false},
                                  {"imu/noise/bias_random_walk", 0.001}}),
                          &options, &error))
      << error;
  EXPECT_TRUE(options.tracker.prediction.use_imu);
  EXPECT_TRUE(options.tracker.prediction.imu.use_orientation);
  EXPECT_EQ(options.tracker.prediction.imu.max_gap, 0.05);
  EXPECT_EQ(options.tracker.prediction.imu.angle_random_walk, 0.001);
  EXPECT_EQ(options.tracker.prediction.imu.bias_sigma, 0.0);
  EXPECT_EQ(options.tracker.prediction.imu.scale_error, 0.05);
  EXPECT_FALSE(options.tracker.prediction.imu.estimate_bias);
  EXPECT_EQ(options.tracker.prediction.imu.bias_random_walk, 0.001);
  EXPECT_NE(summarize(options).find("IMU orientation in"), std::string::npos) << summarize(options);
  EXPECT_EQ(loadError(params({{"imu/max_gap", 0.0}})),
            "parameter ~imu/max_gap must be a number in [0, 10] and > 0, got 0");
  EXPECT_EQ(loadError(params({{"imu/noise/bias_sigma", -0.1}})),
            "parameter ~imu/noise/bias_sigma must be a non-negative number, got -0.1");
  EXPECT_NE(loadError(params({{"use_imu", "yes"}})).find("~use_imu must be true or false"),
            std::string::npos);
}

}  // namespace
}  // namespace hglasm_odometry
