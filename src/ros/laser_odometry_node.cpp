// laser_odometry_node: the same LaserOdometry as the nodelet, in its own process. Exits with status 1
// (after one error naming the parameter) if the parameters are invalid.
#include <ros/ros.h>

#include "hglasm_odometry/ros/laser_odometry.h"
#include "hglasm_odometry/ros/parameters.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "laser_odometry");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  hglasm_odometry::LaserOdometryOptions options;
  std::string error;
  std::vector<std::string> warnings;
  const bool valid = hglasm_odometry::loadOptions(private_nh, &options, &error, &warnings);
  for (const std::string& warning : warnings) ROS_WARN_STREAM(warning);
  if (!valid) {
    ROS_FATAL_STREAM(error << "; laser odometry NOT started");
    return 1;
  }
  hglasm_odometry::LaserOdometry odometry(nh, private_nh, options);
  ros::spin();
  return 0;
}
