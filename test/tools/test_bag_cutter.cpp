// cut_bag's pieces: which scans a slice holds, which relations lie inside it, and the bag it writes.
#include "hglasm_odometry/tools/bag_cutter.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "hglasm_odometry/tools/bag_reader.h"

namespace hglasm_odometry {
namespace {

const std::string kSlice = HGLASM_SOURCE_DIR "/bags/fr079_slice.bag";

TEST(BagCutter, SliceIsAWindowAfterTheFirstStampWithSkipsAndACount) {
  const std::vector<double> stamps = {10.0, 10.5, 11.0, 11.5, 12.0, 12.5, 13.0};
  BagCutOptions options;
  EXPECT_EQ(sliceStamps(stamps, options), stamps);
  options.start = 1.0;
  options.duration = 1.5;
  EXPECT_EQ(sliceStamps(stamps, options), (std::vector<double>{11.0, 11.5, 12.0, 12.5}));
  options.skip_scans = 1;
  options.max_scans = 2;
  EXPECT_EQ(sliceStamps(stamps, options), (std::vector<double>{11.5, 12.0}));
  options.start = 10.0;
  EXPECT_TRUE(sliceStamps(stamps, options).empty());
  EXPECT_TRUE(sliceStamps({}, BagCutOptions()).empty());
}

TEST(BagCutter, KeepsTheRelationsWhoseStampsAreBothScansOfTheSlice) {
  std::istringstream in(
      "1.0 2.0 0.1 0 0 0 0 0\n"
      "2.00005 3.0 0.2 0 0 0 0 0\n"
      "3.0 4.0 0.3 0 0 0 0 0\n"
      "not a relation\n");
  std::ostringstream out;
  std::size_t total = 0;
  EXPECT_EQ(copyRelationsWithin(in, out, {1.0, 2.0, 3.0}, &total), 2u);
  EXPECT_EQ(total, 3u);
  EXPECT_EQ(out.str(), "1.0 2.0 0.1 0 0 0 0 0\n2.00005 3.0 0.2 0 0 0 0 0\n");
}

TEST(BagCutter, NamesAndCompressions) {
  EXPECT_EQ(relationsPathFor("/a/slice.bag"), "/a/slice.relations");
  EXPECT_EQ(relationsPathFor("slice"), "slice.relations");
  rosbag::compression::CompressionType compression = rosbag::compression::BZ2;
  std::string error;
  EXPECT_TRUE(parseCompression("lz4", &compression, &error));
  EXPECT_EQ(compression, rosbag::compression::LZ4);
  EXPECT_FALSE(parseCompression("zip", &compression, &error));
  EXPECT_EQ(error, "unknown compression zip");
}

TEST(BagCutter, WritesTheScansOfTheSliceWithTheirOdometryAndTheMount) {
  rosbag::Bag input(kSlice, rosbag::bagmode::Read);
  BagCutOptions options;
  options.skip_scans = 100;
  options.max_scans = 50;
  options.compression = rosbag::compression::Uncompressed;
  const std::vector<double> stamps = scanStamps(input, options.scan_topic);
  ASSERT_EQ(stamps.size(), 500u);
  const std::vector<double> selected = sliceStamps(stamps, options);
  ASSERT_EQ(selected.size(), 50u);
  const std::string output = testing::TempDir() + "hglasm_cut.bag";
  const CutCounts counts = copySlice(input, output, options, selected.front(), selected.back());
  EXPECT_EQ(counts.scans, 50u);
  EXPECT_GT(counts.odometry, 50u);
  EXPECT_EQ(counts.tf_static, 1u);

  BagData data;
  std::string error;
  ASSERT_TRUE(readBag(output, BagReadOptions(), &data, &error)) << error;
  ASSERT_EQ(data.scans.size(), 50u);
  EXPECT_EQ(data.scans.front().stamp, selected.front());
  EXPECT_LE(data.odometry.front().stamp, selected.front());  // the odometry reaches the first scan
  EXPECT_TRUE(data.has_laser_mount);
  std::remove(output.c_str());
}

}  // namespace
}  // namespace hglasm_odometry
