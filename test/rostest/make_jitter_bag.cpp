// Writes a copy of a bag in which every `every`-th scan (in the bag's order) is stamped 1 ms before the
// scan played ahead of it: a laser driver's jitter, for nodelet_jitter.test. Everything else is copied
// unchanged, at its own receive time. Prints how many scans were re-stamped.
//   usage: make_jitter_bag IN.bag OUT.bag EVERY [SCAN_TOPIC]
#include <cstdio>
#include <cstdlib>
#include <string>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: make_jitter_bag IN.bag OUT.bag EVERY [SCAN_TOPIC]\n");
    return 2;
  }
  const int every = std::atoi(argv[3]);
  const std::string scan_topic = argc > 4 ? argv[4] : "/scan";
  if (every < 2) {
    std::fprintf(stderr, "make_jitter_bag: EVERY must be at least 2\n");
    return 2;
  }
  rosbag::Bag in(argv[1], rosbag::bagmode::Read);
  rosbag::Bag out(argv[2], rosbag::bagmode::Write);
  int scans = 0, restamped = 0;
  ros::Time previous;
  for (const rosbag::MessageInstance& message : rosbag::View(in)) {
    const auto scan =
        message.getTopic() == scan_topic ? message.instantiate<sensor_msgs::LaserScan>() : nullptr;
    if (!scan) {
      out.write(message.getTopic(), message.getTime(), message, message.getConnectionHeader());
      continue;
    }
    sensor_msgs::LaserScan copy = *scan;
    if (scans > 0 && scans % every == 0) {
      copy.header.stamp = previous - ros::Duration(0.001);
      ++restamped;
    }
    previous = scan->header.stamp;
    ++scans;
    out.write(message.getTopic(), message.getTime(), copy);
  }
  out.close();
  std::printf("make_jitter_bag: %d of %d scans stamped 1 ms before the scan ahead of them\n", restamped,
              scans);
  return 0;
}
