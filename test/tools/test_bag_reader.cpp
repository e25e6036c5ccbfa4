// readBag: the base -> laser mount is what tf2 gives the live node, to the last bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

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

/// A bag with one scan in `laser`, base_link -> laser on /tf_static and the wheel odometry's
/// odom -> base_link on /tf, far from the origin (as the fr079 bag has them).
std::string writeBag(const std::string& name) {
  const std::string path = testing::TempDir() + name;
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  tf2_msgs::TFMessage tf, tf_static;
  tf.transforms.push_back(transform("odom", "base_link", 23.1589, -17.0056, -1.0838));
  tf_static.transforms.push_back(transform("base_link", "laser", 0.04, 0.0, 0.0));
  sensor_msgs::LaserScan scan;
  scan.header.stamp = ros::Time(1.0);
  scan.header.frame_id = "laser";
  scan.angle_min = -1.5;
  scan.angle_increment = 0.01;
  scan.range_max = 30.0f;
  scan.ranges.assign(301, 2.0f);
  bag.write("/tf", ros::Time(1.0), tf);
  bag.write("/tf_static", ros::Time(1.0), tf_static);
  bag.write("/scan", ros::Time(1.0), scan);
  bag.close();
  return path;
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

}  // namespace
}  // namespace hglasm_odometry
