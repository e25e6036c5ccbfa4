// The tools' one argument parser: typed and checked values, switches, positionals, --help, and one clear
// line per problem.
#include "hglasm_odometry/tools/argument_parser.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace hglasm_odometry {
namespace {

using Result = ArgumentParser::Result;

struct Parsed {
  Result result = Result::kOk;
  std::string out, err;
};

Parsed run(const ArgumentParser& parser, const std::vector<std::string>& arguments) {
  Parsed parsed;
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  parsed.result = parser.parse(arguments);
  parsed.out = testing::internal::GetCapturedStdout();
  parsed.err = testing::internal::GetCapturedStderr();
  return parsed;
}

TEST(ArgumentParser, FillsTypedOptionsSwitchesAndPositionals) {
  std::string bag;
  bool quiet = false, use_odometry = true, angle_given = false;
  double angle = 0.0;
  int trials = 0;
  std::uint64_t seed = 0;
  std::size_t max_scans = 0;
  std::vector<std::string> files;
  ArgumentParser parser("tool", "usage: tool\n");
  parser.addOption("--bag", &bag);
  parser.addFlag("--quiet", &quiet);
  parser.addFlag("--no-odom", &use_odometry, false);
  parser.addOption("--angle-min", &angle, &angle_given);
  parser.addOption("--trials", &trials, 1);
  parser.addOption("--seed", &seed);
  parser.addOption("--max-scans", &max_scans);
  parser.addPositionals(&files);
  const Parsed parsed =
      run(parser, {"in.bag", "--bag", "b.bag", "--quiet", "--no-odom", "--angle-min", "-1.5", "--trials",
                   "20", "--seed", "18446744073709551615", "--max-scans", "7", "out.bag"});
  ASSERT_EQ(parsed.result, Result::kOk) << parsed.err;
  EXPECT_EQ(bag, "b.bag");
  EXPECT_TRUE(quiet);
  EXPECT_FALSE(use_odometry);
  EXPECT_TRUE(angle_given);
  EXPECT_EQ(angle, -1.5);
  EXPECT_EQ(trials, 20);
  EXPECT_EQ(seed, 18446744073709551615ULL);
  EXPECT_EQ(max_scans, 7u);
  EXPECT_EQ(files, (std::vector<std::string>{"in.bag", "out.bag"}));
}

TEST(ArgumentParser, HelpPrintsTheUsageOnStdout) {
  ArgumentParser parser("tool", "usage: tool --bag B\n");
  for (const char* help : {"--help", "-h"}) {
    const Parsed parsed = run(parser, {help});
    EXPECT_EQ(parsed.result, Result::kHelp);
    EXPECT_EQ(parsed.out, "usage: tool --bag B\n");
    EXPECT_EQ(parsed.err, "");
    EXPECT_EQ(exitStatus(parsed.result), 0);
  }
}

/// The one line a bad command line gives (followed by the pointer to --help).
std::string problem(const ArgumentParser& parser, const std::vector<std::string>& arguments) {
  const Parsed parsed = run(parser, arguments);
  EXPECT_EQ(parsed.result, Result::kError);
  EXPECT_EQ(exitStatus(parsed.result), 2);
  const std::string hint = "\n(tool --help for usage)\n";
  EXPECT_EQ(parsed.err.substr(parsed.err.size() - std::min(parsed.err.size(), hint.size())), hint);
  return parsed.err.substr(0, parsed.err.find('\n'));
}

TEST(ArgumentParser, EveryProblemIsOneLineNamingTheOption) {
  std::string text;
  double number = 0.0;
  int trials = 0;
  std::size_t count = 0;
  ArgumentParser parser("tool", "usage\n");
  parser.addOption("--text", &text);
  parser.addOption("--number", &number);
  parser.addOption("--trials", &trials, 1);
  parser.addOption("--count", &count);
  parser.addOption("--mount", [](const std::string& value, std::string* error) {
    *error = "expects X,Y,YAW, got '" + value + "'";
    return false;
  });
  EXPECT_EQ(problem(parser, {"--text"}), "tool: --text needs a value");
  EXPECT_EQ(problem(parser, {"--bogus"}), "tool: unknown option '--bogus'");
  EXPECT_EQ(problem(parser, {"stray"}), "tool: unexpected argument 'stray'");
  EXPECT_EQ(problem(parser, {"--number", "1.5x"}), "tool: --number: not a number: '1.5x'");
  EXPECT_EQ(problem(parser, {"--number", "inf"}), "tool: --number: not a number: 'inf'");
  EXPECT_EQ(problem(parser, {"--trials", "0"}), "tool: --trials: expected an integer >= 1, got '0'");
  EXPECT_EQ(problem(parser, {"--trials", "2.5"}), "tool: --trials: expected an integer >= 1, got '2.5'");
  EXPECT_EQ(problem(parser, {"--count", "-1"}), "tool: --count: expected a non-negative integer, got '-1'");
  EXPECT_EQ(problem(parser, {"--mount", "1,2"}), "tool: --mount: expects X,Y,YAW, got '1,2'");
}

TEST(ArgumentParser, FailReportsTheToolsOwnChecksTheSameWay) {
  ArgumentParser parser("tool", "usage\n");
  testing::internal::CaptureStderr();
  EXPECT_FALSE(parser.fail("--bag is required"));
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "tool: --bag is required\n(tool --help for usage)\n");
}

}  // namespace
}  // namespace hglasm_odometry
