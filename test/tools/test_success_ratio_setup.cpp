// success_ratio's pieces: its command line into the protocol's options, the base velocity from the wheels,
// the scans it reads and the names of its CSVs.
#include "hglasm_odometry/tools/success_ratio_setup.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace hglasm_odometry {
namespace {

using Result = ArgumentParser::Result;

Result parse(const std::vector<std::string>& arguments, SuccessRatioArguments* args,
             hglasm::SuccessRatioOptions* options) {
  return parseSuccessRatioArguments(arguments, args, options);
}

TEST(SuccessRatioSetup, BuildsTheProtocolsOptions) {
  SuccessRatioArguments args;
  hglasm::SuccessRatioOptions options;
  ASSERT_EQ(parse({"--bag", "b.bag", "--trials", "12", "--seed", "3", "--csv", "x.csv", "--algorithms",
                   "mbicp,hglasm_g,mbicp", "--presets", "large", "--cases", "20:0.57", "--curve-generations",
                   "1,4"},
                  &args, &options),
            Result::kOk);
  EXPECT_EQ(options.algorithms,
            (std::vector<hglasm::Algorithm>{hglasm::Algorithm::kMbicp, hglasm::Algorithm::kHglasmG}));
  EXPECT_EQ(options.presets, (std::vector<hglasm::Preset>{hglasm::Preset::kLarge}));
  EXPECT_EQ(options.cases.size(), 1u);
  EXPECT_EQ(options.trials, 12);
  EXPECT_EQ(options.curve_trials, 12);  // as many as --trials unless given
  EXPECT_EQ(options.seed, 3u);
  EXPECT_EQ(options.curve_generations, (std::vector<int>{1, 4}));
}

TEST(SuccessRatioSetup, RefusesIncompleteOrContradictoryArguments) {
  const std::vector<std::vector<std::string>> bad = {
      {"--trials", "2", "--seed", "1", "--csv", "x.csv"},                                    // no input
      {"--bag", "b", "--carmen", "c", "--trials", "2", "--seed", "1", "--csv", "x.csv"},     // two inputs
      {"--bag", "b", "--seed", "1", "--csv", "x.csv"},                                       // no trials
      {"--carmen", "c", "--topic", "/s", "--trials", "2", "--seed", "1", "--csv", "x.csv"},  // topic of a log
      {"--bag", "b", "--trials", "2", "--seed", "1", "--csv", "x.csv", "--presets", "huge"},
      {"--bag", "b", "--trials", "2", "--seed", "1", "--csv", "x.csv", "--curve-algorithms", "mbicp"},
      {"--bag", "b", "--trials", "2", "--seed", "1", "--csv", "x.csv", "--curve-generations", "0"},
      {"--bag", "b", "--trials", "2", "--seed", "1", "--csv", "x.csv", "--cases", "none", "--curve-trials",
       "0"}};
  for (const auto& arguments : bad) {
    SuccessRatioArguments args;
    hglasm::SuccessRatioOptions options;
    EXPECT_EQ(parse(arguments, &args, &options), Result::kError) << arguments[0] << " " << arguments.back();
  }
}

TEST(SuccessRatioSetup, BaseVelocityIsTheWheelsMotionAroundTheStamp) {
  std::vector<BagOdometry> odometry(3);
  odometry[0].stamp = 0.0;
  odometry[1].stamp = 0.5;
  odometry[1].pose = hglasm::Pose2D(0.5, 0.0, 0.1);
  odometry[2].stamp = 1.0;
  odometry[2].pose = hglasm::Pose2D(1.0, 0.0, 0.3);
  const Eigen::Vector3d first = baseVelocityAt(odometry, 0.2);
  EXPECT_DOUBLE_EQ(first.x(), 1.0);
  EXPECT_DOUBLE_EQ(first.z(), 0.2);
  EXPECT_NEAR(baseVelocityAt(odometry, 0.7).z(), 0.4, 1e-12);
  EXPECT_NEAR(baseVelocityAt(odometry, 5.0).z(), 0.4, 1e-12);  // beyond the samples: the last two
  EXPECT_EQ(baseVelocityAt({odometry[0]}, 0.2), Eigen::Vector3d::Zero());
}

TEST(SuccessRatioSetup, ReadsTheBagsScansWithTheOverrides) {
  SuccessRatioArguments args;
  args.bag = HGLASM_SOURCE_DIR "/bags/fr079_slice.bag";
  args.max_scans = 10;
  args.beam_angles.angle_min_given = true;
  args.beam_angles.angle_min = -1.0;
  std::vector<hglasm::RangeScan> scans;
  std::vector<hglasm::Pose2D> offsets;
  std::ostringstream log;
  std::string error;
  ASSERT_TRUE(readSuccessRatioScans(args, &scans, &offsets, log, &error)) << error;
  ASSERT_EQ(scans.size(), 10u);
  EXPECT_EQ(scans[3].angle_min, -1.0);
  EXPECT_TRUE(offsets.empty());
  EXPECT_EQ(log.str().rfind("success_ratio: read 10 scans on /scan from ", 0), 0u) << log.str();
  args.interlace_seconds = 0.014;  // the odd beams' offsets from the wheels
  ASSERT_TRUE(readSuccessRatioScans(args, &scans, &offsets, log, &error)) << error;
  EXPECT_EQ(offsets.size(), 10u);
}

TEST(SuccessRatioSetup, SiblingCsvReplacesTheExtension) {
  EXPECT_EQ(siblingCsv("out/a.csv", "_evaluations.csv"), "out/a_evaluations.csv");
  EXPECT_EQ(siblingCsv("out/a", "_evaluations.csv"), "out/a_evaluations.csv");
}

}  // namespace
}  // namespace hglasm_odometry
