// catkin_add_gtest links gtest without gtest_main on this Debian: the ROS-layer unit tests bring their main.
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
