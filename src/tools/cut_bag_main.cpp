// cut_bag: copies a slice of a laser bag (a time window and/or a number of scans) into a new, compressed
// bag, and the reference relations that lie entirely inside the slice into <output>.relations.
//
//   cut_bag INPUT.bag OUTPUT.bag [--start SEC] [--duration SEC] [--skip-scans N] [--max-scans N]
//           [--relations FILE] [--scan-topic /scan] [--odom-topic /odom] [--margin SEC]
//           [--compression bz2|lz4|none]
//
// Scans are chosen by header stamp (sorted: some bags store a few out of order): from the first scan at
// or after first_stamp + start, skipping skip-scans, up to max-scans or first_stamp + start + duration.
// Wheel odometry and /tf are copied for the slice's time span widened by --margin (so odometry can be
// interpolated at the first and last scan); /tf_static is always copied, moved to the start of the slice
// and marked latched (so a player does not wait through the skipped part and late subscribers get it).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>

#include "hglasm_odometry/tools/argument_parser.h"

namespace {

struct Options {
  std::string input;
  std::string output;
  double start = 0.0;
  double duration = std::numeric_limits<double>::infinity();
  std::size_t skip_scans = 0;
  std::size_t max_scans = std::numeric_limits<std::size_t>::max();
  std::string relations;
  std::string scan_topic = "/scan";
  std::string odom_topic = "/odom";
  double margin = 1.0;
  rosbag::compression::CompressionType compression = rosbag::compression::BZ2;
};

const char kUsage[] =
    "usage: cut_bag INPUT.bag OUTPUT.bag [--start SEC] [--duration SEC] [--skip-scans N]\n"
    "               [--max-scans N] [--relations FILE] [--scan-topic /scan] [--odom-topic /odom]\n"
    "               [--margin SEC] [--compression bz2|lz4|none]\n";

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

/// kOk with *options filled, or what the tool should exit with.
hglasm_odometry::ArgumentParser::Result parseArguments(int argc, char** argv, Options* options) {
  using Result = hglasm_odometry::ArgumentParser::Result;
  hglasm_odometry::ArgumentParser parser("cut_bag", kUsage);
  std::vector<std::string> positional;
  parser.addPositionals(&positional);
  parser.addOption("--start", &options->start);
  parser.addOption("--duration", &options->duration);
  parser.addOption("--skip-scans", &options->skip_scans);
  parser.addOption("--max-scans", &options->max_scans);
  parser.addOption("--relations", &options->relations);
  parser.addOption("--scan-topic", &options->scan_topic);
  parser.addOption("--odom-topic", &options->odom_topic);
  parser.addOption("--margin", &options->margin);
  parser.addOption("--compression", [options](const std::string& name, std::string* error) {
    return parseCompression(name, &options->compression, error);
  });
  const Result result = parser.parse(argc, argv);
  if (result != Result::kOk) return result;
  if (positional.size() != 2) {
    parser.fail("expected two file names, INPUT.bag and OUTPUT.bag; got " +
                std::to_string(positional.size()));
    return Result::kError;
  }
  options->input = positional[0];
  options->output = positional[1];
  return Result::kOk;
}

/// Header stamp of a message on one of the copied topics; bag time when it has none.
double stampOf(const rosbag::MessageInstance& m) {
  if (auto scan = m.instantiate<sensor_msgs::LaserScan>()) return scan->header.stamp.toSec();
  return m.getTime().toSec();
}

std::string relationsPathFor(const std::string& bag_path) {
  const std::string suffix = ".bag";
  std::string base = bag_path;
  if (base.size() > suffix.size() && base.compare(base.size() - suffix.size(), suffix.size(), suffix) == 0) {
    base.resize(base.size() - suffix.size());
  }
  return base + ".relations";
}

bool matchesStamp(const std::vector<double>& sorted_stamps, double t) {
  constexpr double kTolerance = 1e-4;  // relations carry stamps to 1e-6 s
  auto it = std::lower_bound(sorted_stamps.begin(), sorted_stamps.end(), t - kTolerance);
  return it != sorted_stamps.end() && *it <= t + kTolerance;
}

/// Pass 1: the stamps of the scans in the slice, sorted (empty, with a message, if there are none).
std::vector<double> selectScans(rosbag::Bag& input, const Options& options) {
  std::vector<double> stamps;
  {
    rosbag::View scans(input, rosbag::TopicQuery(options.scan_topic));
    for (const rosbag::MessageInstance& m : scans) stamps.push_back(stampOf(m));
  }
  if (stamps.empty()) {
    std::cerr << "cut_bag: no messages on " << options.scan_topic << " in " << options.input << "\n";
    return {};
  }
  std::sort(stamps.begin(), stamps.end());
  const double window_start = stamps.front() + options.start;
  const double window_end = window_start + options.duration;
  std::vector<double> selected;
  std::size_t skipped = 0;
  for (double stamp : stamps) {
    if (stamp < window_start) continue;
    if (stamp > window_end || selected.size() >= options.max_scans) break;
    if (skipped < options.skip_scans) {
      ++skipped;
      continue;
    }
    selected.push_back(stamp);
  }
  if (selected.empty()) std::cerr << "cut_bag: the requested slice holds no scans\n";
  return selected;
}

/// Pass 2: copies the scans stamped first..last, odometry and tf within the margin around them, and every
/// tf_static message (latched, at the slice's start).
void copySlice(rosbag::Bag& input, const Options& options, double first, double last) {
  const ros::Time tf_static_time(std::max(0.0, first - options.margin));
  rosbag::Bag output(options.output, rosbag::bagmode::Write);
  output.setCompression(options.compression);
  std::size_t scan_count = 0, odom_count = 0, tf_count = 0, tf_static_count = 0;
  rosbag::View all(input);
  for (const rosbag::MessageInstance& m : all) {
    const std::string& topic = m.getTopic();
    if (topic == "/tf_static") {
      auto header = boost::make_shared<ros::M_string>(*m.getConnectionHeader());
      (*header)["latching"] = "1";
      output.write(topic, tf_static_time, m, header);
      ++tf_static_count;
    } else if (topic == options.scan_topic) {
      const double stamp = stampOf(m);
      if (stamp < first || stamp > last) continue;
      output.write(topic, m.getTime(), m, m.getConnectionHeader());
      ++scan_count;
    } else if (topic == options.odom_topic || topic == "/tf") {
      const double t = m.getTime().toSec();
      if (t < first - options.margin || t > last + options.margin) continue;
      output.write(topic, m.getTime(), m, m.getConnectionHeader());
      ++(topic == "/tf" ? tf_count : odom_count);
    }
  }
  output.close();
  std::cout << "cut_bag: wrote " << options.output << ": " << scan_count << " scans (" << std::fixed
            << (last - first) << " s from stamp " << first << "), " << odom_count << " odometry, " << tf_count
            << " tf, " << tf_static_count << " tf_static messages\n";
}

/// The relations of options.relations whose both stamps are scans of the slice, next to the output bag.
bool cutRelations(const Options& options, const std::vector<double>& selected) {
  std::ifstream in(options.relations);
  if (!in) {
    std::cerr << "cut_bag: cannot read " << options.relations << "\n";
    return false;
  }
  const std::string relations_out = relationsPathFor(options.output);
  std::ofstream out(relations_out);
  std::size_t kept = 0, total = 0;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double t1 = 0.0, t2 = 0.0;
    if (!(fields >> t1 >> t2)) continue;
    ++total;
    if (matchesStamp(selected, t1) && matchesStamp(selected, t2)) {
      out << line << "\n";
      ++kept;
    }
  }
  if (!out) {
    std::cerr << "cut_bag: cannot write " << relations_out << "\n";
    return false;
  }
  std::cout << "cut_bag: wrote " << relations_out << ": " << kept << " of " << total
            << " relations lie inside the slice\n";
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  const auto parsed = parseArguments(argc, argv, &options);
  if (parsed != hglasm_odometry::ArgumentParser::Result::kOk) return hglasm_odometry::exitStatus(parsed);
  try {
    rosbag::Bag input(options.input, rosbag::bagmode::Read);
    const std::vector<double> selected = selectScans(input, options);
    if (selected.empty()) return 1;
    copySlice(input, options, selected.front(), selected.back());
    if (!options.relations.empty() && !cutRelations(options, selected)) return 1;
  } catch (const rosbag::BagException& ex) {
    std::cerr << "cut_bag: " << ex.what() << "\n";
    return 1;
  }
  return 0;
}
