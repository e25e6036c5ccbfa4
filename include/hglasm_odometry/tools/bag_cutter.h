// Cutting a slice of a laser bag (a time window and/or a number of scans) into a new bag, with the
// reference relations that lie inside it: what cut_bag does to make the slices in bags/.
#pragma once

#include <cstddef>
#include <istream>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include <rosbag/bag.h>

namespace hglasm_odometry {

struct BagCutOptions {
  double start = 0.0;  ///< seconds after the first scan's stamp
  double duration = std::numeric_limits<double>::infinity();
  std::size_t skip_scans = 0;  ///< scans skipped from the start of the window
  std::size_t max_scans = std::numeric_limits<std::size_t>::max();
  std::string scan_topic = "/scan";
  std::string odom_topic = "/odom";
  double margin = 1.0;  ///< seconds of odometry and tf copied beyond the first and last scan
  rosbag::compression::CompressionType compression = rosbag::compression::BZ2;
};

/// bz2, lz4 or none.
bool parseCompression(const std::string& name, rosbag::compression::CompressionType* compression,
                      std::string* error);

/// The header stamps of the scans on `topic`, sorted (some bags store a few out of order).
std::vector<double> scanStamps(rosbag::Bag& input, const std::string& topic);

/// The slice of `sorted_stamps`: from the first at or after the first stamp + start, skipping skip_scans,
/// up to max_scans or the first stamp + start + duration.
std::vector<double> sliceStamps(const std::vector<double>& sorted_stamps, const BagCutOptions& options);

struct CutCounts {
  std::size_t scans = 0, odometry = 0, tf = 0, tf_static = 0;
};

/// Writes `output`: the scans stamped first..last, odometry and /tf received within the margin around
/// them, and every /tf_static message moved to the slice's start and latched (so a player does not wait
/// through the skipped part and late subscribers get it).
CutCounts copySlice(rosbag::Bag& input, const std::string& output, const BagCutOptions& options, double first,
                    double last);

/// Copies the relation lines ('t1 t2 ...') of `in` whose stamps are both in `stamps` (sorted, within
/// 1e-4 s) to `out`; the count copied, *total the count read.
std::size_t copyRelationsWithin(std::istream& in, std::ostream& out, const std::vector<double>& stamps,
                                std::size_t* total);

/// The relations file beside a bag: x.bag -> x.relations.
std::string relationsPathFor(const std::string& bag_path);

}  // namespace hglasm_odometry
