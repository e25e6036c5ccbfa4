// The CARMEN FLASER parser: synthetic lines with known contents, malformed lines, and the real laserazos log.
#include "hglasm_odometry/evaluation/carmen_log.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "../core/test_util.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {
namespace {

const char* const kGoodLine = "FLASER 5 1.5 2.25 NaN 4 5.125 0.5 -1.25 0.75 10 20 -3.0 12.5 myhost 13.0";

TEST(CarmenLog, ParsesAllFieldsOfALine) {
  CarmenLaserReading reading;
  ASSERT_TRUE(parseCarmenLaserLine(kGoodLine, CarmenLogOptions(), &reading));
  ASSERT_EQ(reading.ranges.ranges.size(), 5u);
  EXPECT_FLOAT_EQ(reading.ranges.ranges[0], 1.5f);
  EXPECT_FLOAT_EQ(reading.ranges.ranges[1], 2.25f);
  EXPECT_TRUE(std::isnan(reading.ranges.ranges[2]));
  EXPECT_FLOAT_EQ(reading.ranges.ranges[3], 4.0f);
  EXPECT_FLOAT_EQ(reading.ranges.ranges[4], 5.125f);
  // Five beams over -90..+90 degrees: 45 degrees apart.
  EXPECT_DOUBLE_EQ(reading.ranges.angle_min, -M_PI / 2);
  EXPECT_DOUBLE_EQ(reading.ranges.angle_increment, M_PI / 4);
  EXPECT_DOUBLE_EQ(reading.ranges.range_max, 80.0);
  EXPECT_DOUBLE_EQ(reading.laser_pose.x, 0.5);
  EXPECT_DOUBLE_EQ(reading.laser_pose.y, -1.25);
  EXPECT_DOUBLE_EQ(reading.laser_pose.theta, 0.75);
  EXPECT_DOUBLE_EQ(reading.odometry_pose.x, 10.0);
  EXPECT_DOUBLE_EQ(reading.odometry_pose.y, 20.0);
  EXPECT_DOUBLE_EQ(reading.odometry_pose.theta, -3.0);
  EXPECT_DOUBLE_EQ(reading.stamp, 12.5);
}

TEST(CarmenLog, NanReadingsBecomeInvalidBeams) {
  CarmenLaserReading reading;
  ASSERT_TRUE(parseCarmenLaserLine(kGoodLine, CarmenLogOptions(), &reading));
  const Scan scan = scanFromRanges(reading.ranges);
  EXPECT_EQ(scan.size(), 4u);
  EXPECT_EQ(scan.invalid_count, 1);
  // Beam 0 at -90 degrees, 1.5 m: (0, -1.5). Beam 4 at +90 degrees: (0, 5.125).
  EXPECT_NEAR(scan.points.front().x(), 0.0, 1e-9);
  EXPECT_NEAR(scan.points.front().y(), -1.5, 1e-9);
  EXPECT_NEAR(scan.points.back().y(), 5.125, 1e-6);
}

TEST(CarmenLog, CallerOverridesAngles) {
  CarmenLogOptions options;
  options.angle_min = -1.0;
  options.angle_increment = 0.01;
  CarmenLaserReading reading;
  ASSERT_TRUE(parseCarmenLaserLine(kGoodLine, options, &reading));
  EXPECT_DOUBLE_EQ(reading.ranges.angle_min, -1.0);
  EXPECT_DOUBLE_EQ(reading.ranges.angle_increment, 0.01);

  options = CarmenLogOptions();
  options.field_of_view = M_PI / 2;
  ASSERT_TRUE(parseCarmenLaserLine(kGoodLine, options, &reading));
  EXPECT_DOUBLE_EQ(reading.ranges.angle_increment, M_PI / 8);
}

TEST(CarmenLog, TrailingFieldsAreOptional) {
  CarmenLaserReading reading;
  ASSERT_TRUE(parseCarmenLaserLine("FLASER 2 1 2 0 0 0 0 0 0", CarmenLogOptions(), &reading));
  EXPECT_EQ(reading.ranges.ranges.size(), 2u);
  EXPECT_DOUBLE_EQ(reading.stamp, 0.0);
  // Windows line ends and tabs are whitespace.
  ASSERT_TRUE(parseCarmenLaserLine("FLASER\t2 1 2 0 0 0 0 0 0 7.5 h 8\r", CarmenLogOptions(), &reading));
  EXPECT_DOUBLE_EQ(reading.stamp, 7.5);
}

TEST(CarmenLog, RejectsMalformedLines) {
  const CarmenLogOptions options;
  CarmenLaserReading reading;
  for (const char* line : {
           "",                                             // empty
           "ODOM 1 2 3 0 0 0 0 host 0",                    // another message
           "FLASER",                                       // no beam count
           "FLASER x 1 2 0 0 0 0 0 0",                     // beam count not a number
           "FLASER 0 0 0 0 0 0 0",                         // no beams
           "FLASER -3 1 2 3 0 0 0 0 0 0",                  // negative count
           "FLASER 99999999 1 2 3",                        // absurd count
           "FLASER 3 1 2 0 0 0 0 0 0",                     // one reading short: poses run out
           "FLASER 2 1 2 0 0 0 0 0",                       // a pose field missing
           "FLASER 2 1 abc 0 0 0 0 0 0 0 h 0",             // a reading that is not a number
           "FLASER 2 1 2.5.3 0 0 0 0 0 0",                 // trailing garbage in a number
           "FLASER 2 1 2 0 NaN 0 0 0 0",                   // non-finite pose
           "FLASER 2 1 2 0 0 0 0 0 0 1 h 2 extra fields",  // too many fields: count does not match
           "FLASER 2.5 1 2 0 0 0 0 0 0",                   // fractional count
       }) {
    EXPECT_FALSE(parseCarmenLaserLine(line, options, &reading)) << "line: '" << line << "'";
  }
}

TEST(CarmenLog, ReadsStreamsSkippingAndCountingBadLines) {
  std::istringstream log(std::string("# a comment\n") + kGoodLine + "\n" +
                         "ODOM 1 2 3 0 0 0 0 host 0\n"
                         "\n"
                         "FLASER 3 1 2 0 0 0 0 0 0\n" +  // malformed (line 5)
                         kGoodLine +
                         "\n" + "FLASER 2 1 2 0 0 0 0 0 0 1 h 2 3 4\n" +  // malformed (line 7)
                         "FLASER 2 7 8 0 0 0 0 0 0");                     // last line without newline
  CarmenLog parsed;
  std::string error;
  ASSERT_TRUE(readCarmenLog(log, CarmenLogOptions(), &parsed, &error)) << error;
  ASSERT_EQ(parsed.scans.size(), 3u);
  EXPECT_EQ(parsed.malformed_lines, 2u);
  EXPECT_EQ(parsed.first_malformed_line, 5u);
  EXPECT_EQ(parsed.ignored_lines, 3u);  // comment, ODOM, blank
  EXPECT_EQ(parsed.scans[0].line_number, 2u);
  EXPECT_EQ(parsed.scans[1].line_number, 6u);
  EXPECT_EQ(parsed.scans[2].line_number, 8u);
  EXPECT_FLOAT_EQ(parsed.scans[2].ranges.ranges[1], 8.0f);
}

TEST(CarmenLog, MaxScansStopsEarlyAndOtherMessagesCanBeSelected) {
  const std::string text = std::string(kGoodLine) + "\nRLASER 2 3 4 0 0 0 0 0 0\n" + kGoodLine + "\n";
  CarmenLogOptions options;
  options.max_scans = 1;
  CarmenLog parsed;
  std::istringstream first(text);
  ASSERT_TRUE(readCarmenLog(first, options, &parsed, nullptr));
  EXPECT_EQ(parsed.scans.size(), 1u);

  options = CarmenLogOptions();
  options.message = "RLASER";
  std::istringstream second(text);
  ASSERT_TRUE(readCarmenLog(second, options, &parsed, nullptr));
  ASSERT_EQ(parsed.scans.size(), 1u);
  EXPECT_FLOAT_EQ(parsed.scans[0].ranges.ranges[0], 3.0f);
  EXPECT_EQ(parsed.ignored_lines, 2u);
}

TEST(CarmenLog, MissingFileIsAnError) {
  CarmenLog parsed;
  std::string error;
  EXPECT_FALSE(readCarmenLog("/nonexistent/dir/no.log", CarmenLogOptions(), &parsed, &error));
  EXPECT_NE(error.find("/nonexistent/dir/no.log"), std::string::npos);
  EXPECT_TRUE(parsed.scans.empty());
}

TEST(CarmenLog, ReadsTheRealLaserazosLog) {
  const std::string path = hglasm_test::datasetPath("laserazos/laserazosSM3.log");
  if (!std::ifstream(path)) GTEST_SKIP() << "dataset not present: " << path;
  CarmenLog parsed;
  std::string error;
  ASSERT_TRUE(readCarmenLog(path, CarmenLogOptions(), &parsed, &error)) << error;
  EXPECT_EQ(parsed.scans.size(), 778u);
  EXPECT_EQ(parsed.malformed_lines, 0u);

  // The first line, checked against its text: first reading 3.727 m, poses at the end of the line.
  std::ifstream in(path);
  std::string first_line;
  std::getline(in, first_line);
  std::istringstream fields(first_line);
  std::string tag;
  int beams = 0;
  fields >> tag >> beams;
  ASSERT_EQ(beams, 361);
  std::vector<std::string> tokens;
  for (std::string token; fields >> token;) tokens.push_back(token);
  ASSERT_EQ(tokens.size(), 361u + 9u);
  const CarmenLaserReading& reading = parsed.scans.front();
  EXPECT_FLOAT_EQ(reading.ranges.ranges[0], std::stof(tokens[0]));
  EXPECT_FLOAT_EQ(reading.ranges.ranges[360], std::stof(tokens[360]));
  EXPECT_DOUBLE_EQ(reading.laser_pose.x, std::stod(tokens[361]));
  EXPECT_DOUBLE_EQ(reading.laser_pose.y, std::stod(tokens[362]));
  EXPECT_NEAR(reading.laser_pose.theta, std::stod(tokens[363]), 1e-12);
  EXPECT_DOUBLE_EQ(reading.odometry_pose.x, std::stod(tokens[364]));
  EXPECT_EQ(reading.line_number, 1u);

  // 0.5-degree beams over -90..+90 degrees; NaN readings exist and are invalid.
  EXPECT_NEAR(reading.ranges.angle_increment, M_PI / 360.0, 1e-15);
  std::size_t scans_with_nan = 0;
  std::size_t points = 0;
  for (const CarmenLaserReading& scan : parsed.scans) {
    ASSERT_EQ(scan.ranges.ranges.size(), 361u);
    bool has_nan = false;
    for (float r : scan.ranges.ranges) has_nan = has_nan || std::isnan(r);
    scans_with_nan += has_nan ? 1 : 0;
    const Scan converted = scanFromRanges(scan.ranges);
    for (const Eigen::Vector2d& p : converted.points) ASSERT_TRUE(p.allFinite());
    points += converted.size();
  }
  EXPECT_GT(scans_with_nan, 0u);
  EXPECT_GT(points, 778u * 100u);  // mostly valid indoor scans
}

}  // namespace
}  // namespace hglasm
