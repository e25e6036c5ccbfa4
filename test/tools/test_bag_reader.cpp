// readBag: the base -> laser mount is what tf2 gives the live node, to the last bit, and which transforms
// of a bag it is taken from.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2_msgs/TFMessage.h>

#include "hglasm_odometry/tools/bag_reader.h"

namespace hglasm_odometry {
namespace {

geometry_msgs::TransformStamped transform(const std::string& parent, const std::string& child, double x,
                                          double y, double yaw) {
  geometry_msgs::TransformStamped stamped;
  stamped.header.stamp = ros::Time(1.0);
  stamped.header.frame_id = parent;
  stamped.child_frame_id = child;
  stamped.transform.translation.x = x;
  stamped.transform.translation.y = y;
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, yaw);
  stamped.transform.rotation.x = q.x();
  stamped.transform.rotation.y = q.y();
  stamped.transform.rotation.z = q.z();
  stamped.transform.rotation.w = q.w();
  return stamped;
}

/// One scan in `scan_frame` at t = 1 s after the given /tf and /tf_static messages.
std::string writeBag(const std::string& name, const std::vector<tf2_msgs::TFMessage>& tf,
                     const std::vector<tf2_msgs::TFMessage>& tf_static,
                     const std::string& scan_frame = "laser") {
  const std::string path = testing::TempDir() + name;
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (const auto& message : tf) bag.write("/tf", ros::Time(1.0), message);
  for (const auto& message : tf_static) bag.write("/tf_static", ros::Time(1.0), message);
  sensor_msgs::LaserScan scan;
  scan.header.stamp = ros::Time(1.0);
  scan.header.frame_id = scan_frame;
  scan.angle_min = -1.5;
  scan.angle_increment = 0.01;
  scan.range_max = 30.0f;
  scan.ranges.assign(301, 2.0f);
  bag.write("/scan", ros::Time(1.0), scan);
  bag.close();
  return path;
}

tf2_msgs::TFMessage message(std::initializer_list<geometry_msgs::TransformStamped> transforms) {
  tf2_msgs::TFMessage tf;
  tf.transforms = transforms;
  return tf;
}

/// A bag with one scan in `laser`, base_link -> laser on /tf_static and the wheel odometry's
/// odom -> base_link on /tf, far from the origin (as the fr079 bag has them).
std::string writeBag(const std::string& name) {
  return writeBag(name, {message({transform("odom", "base_link", 23.1589, -17.0056, -1.0838)})},
                  {message({transform("base_link", "laser", 0.04, 0.0, 0.0)})});
}

BagData read(const std::string& path) {
  BagData data;
  std::string error;
  EXPECT_TRUE(readBag(path, BagReadOptions(), &data, &error)) << error;
  std::remove(path.c_str());
  return data;
}

void expectMount(const BagData& data, double x, double y, double theta) {
  ASSERT_TRUE(data.has_laser_mount);
  EXPECT_NEAR(data.base_to_laser.x, x, 1e-12);
  EXPECT_NEAR(data.base_to_laser.y, y, 1e-12);
  EXPECT_NEAR(data.base_to_laser.theta, theta, 1e-12);
}

TEST(BagReader, LaserMountIsComposedWithoutADetourThroughTheOdometryFrame) {
  const std::string path = writeBag("hglasm_bag_reader_mount.bag");
  BagData data;
  std::string error;
  ASSERT_TRUE(readBag(path, BagReadOptions(), &data, &error)) << error;
  std::remove(path.c_str());
  ASSERT_TRUE(data.has_laser_mount);
  EXPECT_EQ(data.base_frame, "base_link");
  // Exactly tf2's answer: the static transform itself (through odom -> base_link it was 0.0400000000000027).
  EXPECT_EQ(data.base_to_laser.x, 0.04);
  EXPECT_EQ(data.base_to_laser.y, 0.0);
  EXPECT_EQ(data.base_to_laser.theta, 0.0);
  EXPECT_FALSE(data.laser_upside_down);
}

TEST(BagReader, ChainOfMountsIsComposed) {
  const BagData data = read(writeBag("hglasm_bag_reader_chain.bag", {},
                                     {message({transform("base_link", "plate", 0.1, 0.0, 0.5),
                                               transform("plate", "laser", 0.2, 0.05, -0.2)})}));
  const hglasm::Pose2D expected = hglasm::Pose2D(0.1, 0.0, 0.5) * hglasm::Pose2D(0.2, 0.05, -0.2);
  expectMount(data, expected.x, expected.y, expected.theta);
}

TEST(BagReader, MountOnTfOnlyIsTheFirstOfItsFrame) {
  const BagData data = read(writeBag("hglasm_bag_reader_tf_only.bag",
                                     {message({transform("odom", "base_link", 3.0, 1.0, 0.3),
                                               transform("base_link", "laser", 0.1, 0.0, 0.0)}),
                                      message({transform("base_link", "laser", 0.7, 0.0, 0.0)})},
                                     {}));
  expectMount(data, 0.1, 0.0, 0.0);
}

TEST(BagReader, TfStaticWinsOverTfAndTheLatestStaticWins) {
  const BagData data = read(writeBag("hglasm_bag_reader_static_wins.bag",
                                     {message({transform("base_link", "laser", 0.7, 0.0, 0.0)})},
                                     {message({transform("base_link", "laser", 0.2, 0.0, 0.0)}),
                                      message({transform("base_link", "laser", 0.3, 0.0, 0.1)})}));
  expectMount(data, 0.3, 0.0, 0.1);
}

TEST(BagReader, UnsetOrUnnormalisedRotationIsAccepted) {
  geometry_msgs::TransformStamped unset = transform("base_link", "laser", 0.1, 0.0, 0.0);
  unset.transform.rotation.w = 0.0;
  expectMount(read(writeBag("hglasm_bag_reader_unset.bag", {}, {message({unset})})), 0.1, 0.0, 0.0);
  geometry_msgs::TransformStamped scaled = transform("base_link", "laser", 0.1, 0.0, 0.4);
  scaled.transform.rotation.z *= 2.0;
  scaled.transform.rotation.w *= 2.0;
  expectMount(read(writeBag("hglasm_bag_reader_scaled.bag", {}, {message({scaled})})), 0.1, 0.0, 0.4);
}

TEST(BagReader, LeadingSlashesAreIgnored) {
  const BagData data =
      read(writeBag("hglasm_bag_reader_slashes.bag", {},
                    {message({transform("/base_link", "/laser", 0.1, 0.2, 0.3)})}, "/laser"));
  expectMount(data, 0.1, 0.2, 0.3);
  EXPECT_EQ(data.scans.front().frame_id, "laser");
}

TEST(BagReader, UpsideDownLaserIsMirrored) {
  geometry_msgs::TransformStamped flipped = transform("base_link", "laser", 0.1, 0.0, 0.0);
  flipped.transform.rotation.x = 1.0;  // roll pi: the laser's z axis points down
  flipped.transform.rotation.w = 0.0;
  const BagData data = read(writeBag("hglasm_bag_reader_flipped.bag", {}, {message({flipped})}));
  expectMount(data, 0.1, 0.0, 0.0);
  EXPECT_TRUE(data.laser_upside_down);
}

TEST(BagReader, UnconnectedLaserHasNoMount) {
  const BagData data = read(writeBag("hglasm_bag_reader_unconnected.bag", {},
                                     {message({transform("base_link", "camera", 0.1, 0.0, 0.0)})}));
  EXPECT_FALSE(data.has_laser_mount);
  EXPECT_EQ(data.base_to_laser.x, 0.0);
  EXPECT_EQ(data.base_to_laser.theta, 0.0);
}

TEST(BagReader, LaserThatIsTheBaseIsMountedAtTheOrigin) {
  const BagData data = read(writeBag("hglasm_bag_reader_base.bag", {}, {}, "base_link"));
  expectMount(data, 0.0, 0.0, 0.0);
}

TEST(BagReader, NonFiniteTransformIsIgnored) {
  geometry_msgs::TransformStamped broken = transform("base_link", "laser", 0.1, 0.0, 0.0);
  broken.transform.translation.y = std::nan("");
  const BagData data = read(writeBag("hglasm_bag_reader_nan.bag", {}, {message({broken})}));
  EXPECT_FALSE(data.has_laser_mount);
}

}  // namespace
}  // namespace hglasm_odometry
