#include "hglasm_odometry/tools/bag_cutter.h"

#include <algorithm>
#include <sstream>

#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>

namespace hglasm_odometry {
namespace {

/// Header stamp of a message on one of the copied topics; bag time when it has none.
double stampOf(const rosbag::MessageInstance& m) {
  if (auto scan = m.instantiate<sensor_msgs::LaserScan>()) return scan->header.stamp.toSec();
  return m.getTime().toSec();
}

bool matchesStamp(const std::vector<double>& sorted_stamps, double t) {
  constexpr double kTolerance = 1e-4;  // relations carry stamps to 1e-6 s
  auto it = std::lower_bound(sorted_stamps.begin(), sorted_stamps.end(), t - kTolerance);
  return it != sorted_stamps.end() && *it <= t + kTolerance;
}

}  // namespace

bool parseCompression(const std::string& name, rosbag::compression::CompressionType* compression,
                      std::string* error) {
  if (name == "bz2") {
    *compression = rosbag::compression::BZ2;
  } else if (name == "lz4") {
    *compression = rosbag::compression::LZ4;
  } else if (name == "none") {
    *compression = rosbag::compression::Uncompressed;
  } else {
    *error = "unknown compression " + name;
    return false;
  }
  return true;
}

std::vector<double> scanStamps(rosbag::Bag& input, const std::string& topic) {
  std::vector<double> stamps;
  for (const rosbag::MessageInstance& m : rosbag::View(input, rosbag::TopicQuery(topic)))
    stamps.push_back(stampOf(m));
  std::sort(stamps.begin(), stamps.end());
  return stamps;
}

std::vector<double> sliceStamps(const std::vector<double>& sorted_stamps, const BagCutOptions& options) {
  std::vector<double> selected;
  if (sorted_stamps.empty()) return selected;
  const double window_start = sorted_stamps.front() + options.start;
  const double window_end = window_start + options.duration;
  std::size_t skipped = 0;
  for (double stamp : sorted_stamps) {
    if (stamp < window_start) continue;
    if (stamp > window_end || selected.size() >= options.max_scans) break;
    if (skipped < options.skip_scans) {
      ++skipped;
      continue;
    }
    selected.push_back(stamp);
  }
  return selected;
}

CutCounts copySlice(rosbag::Bag& input, const std::string& output_path, const BagCutOptions& options,
                    double first, double last) {
  const ros::Time tf_static_time(std::max(0.0, first - options.margin));
  rosbag::Bag output(output_path, rosbag::bagmode::Write);
  output.setCompression(options.compression);
  CutCounts counts;
  for (const rosbag::MessageInstance& m : rosbag::View(input)) {
    const std::string& topic = m.getTopic();
    if (topic == "/tf_static") {
      auto header = boost::make_shared<ros::M_string>(*m.getConnectionHeader());
      (*header)["latching"] = "1";
      output.write(topic, tf_static_time, m, header);
      ++counts.tf_static;
    } else if (topic == options.scan_topic) {
      const double stamp = stampOf(m);
      if (stamp < first || stamp > last) continue;
      output.write(topic, m.getTime(), m, m.getConnectionHeader());
      ++counts.scans;
    } else if (topic == options.odom_topic || topic == "/tf") {
      const double t = m.getTime().toSec();
      if (t < first - options.margin || t > last + options.margin) continue;
      output.write(topic, m.getTime(), m, m.getConnectionHeader());
      ++(topic == "/tf" ? counts.tf : counts.odometry);
    }
  }
  output.close();
  return counts;
}

std::size_t copyRelationsWithin(std::istream& in, std::ostream& out, const std::vector<double>& stamps,
                                std::size_t* total) {
  std::size_t kept = 0;
  *total = 0;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double t1 = 0.0, t2 = 0.0;
    if (!(fields >> t1 >> t2)) continue;
    ++*total;
    if (matchesStamp(stamps, t1) && matchesStamp(stamps, t2)) {
      out << line << "\n";
      ++kept;
    }
  }
  return kept;
}

std::string relationsPathFor(const std::string& bag_path) {
  const std::string suffix = ".bag";
  std::string base = bag_path;
  if (base.size() > suffix.size() && base.compare(base.size() - suffix.size(), suffix.size(), suffix) == 0) {
    base.resize(base.size() - suffix.size());
  }
  return base + ".relations";
}

}  // namespace hglasm_odometry
