// cut_bag: copies a slice of a laser bag (a time window and/or a number of scans) into a new, compressed
// bag, and the reference relations that lie entirely inside the slice into <output>.relations.
//
//   cut_bag INPUT.bag OUTPUT.bag [--start SEC] [--duration SEC] [--skip-scans N] [--max-scans N]
//           [--relations FILE] [--scan-topic /scan] [--odom-topic /odom] [--margin SEC]
//           [--compression bz2|lz4|none]
//
// The slice and what is copied with it: tools/bag_cutter.h.
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "hglasm_odometry/tools/argument_parser.h"
#include "hglasm_odometry/tools/bag_cutter.h"

namespace hglasm_odometry {
namespace {

const char kUsage[] =
    "usage: cut_bag INPUT.bag OUTPUT.bag [--start SEC] [--duration SEC] [--skip-scans N]\n"
    "               [--max-scans N] [--relations FILE] [--scan-topic /scan] [--odom-topic /odom]\n"
    "               [--margin SEC] [--compression bz2|lz4|none]\n";

struct Arguments {
  std::string input, output, relations;
  BagCutOptions cut;
};

/// kOk with *args filled, or what the tool should exit with.
ArgumentParser::Result parseArguments(int argc, char** argv, Arguments* args) {
  ArgumentParser parser("cut_bag", kUsage);
  std::vector<std::string> positional;
  parser.addPositionals(&positional);
  parser.addOption("--start", &args->cut.start);
  parser.addOption("--duration", &args->cut.duration);
  parser.addOption("--skip-scans", &args->cut.skip_scans);
  parser.addOption("--max-scans", &args->cut.max_scans);
  parser.addOption("--relations", &args->relations);
  parser.addOption("--scan-topic", &args->cut.scan_topic);
  parser.addOption("--odom-topic", &args->cut.odom_topic);
  parser.addOption("--margin", &args->cut.margin);
  parser.addOption("--compression", [args](const std::string& name, std::string* error) {
    return parseCompression(name, &args->cut.compression, error);
  });
  const ArgumentParser::Result result = parser.parse(argc, argv);
  if (result != ArgumentParser::Result::kOk) return result;
  if (positional.size() != 2) {
    parser.fail("expected two file names, INPUT.bag and OUTPUT.bag; got " +
                std::to_string(positional.size()));
    return ArgumentParser::Result::kError;
  }
  args->input = positional[0];
  args->output = positional[1];
  return ArgumentParser::Result::kOk;
}

/// The relations of args.relations whose both stamps are scans of the slice, next to the output bag.
bool cutRelations(const Arguments& args, const std::vector<double>& selected) {
  std::ifstream in(args.relations);
  if (!in) {
    std::cerr << "cut_bag: cannot read " << args.relations << "\n";
    return false;
  }
  const std::string relations_out = relationsPathFor(args.output);
  std::ofstream out(relations_out);
  std::size_t total = 0;
  const std::size_t kept = copyRelationsWithin(in, out, selected, &total);
  if (!out) {
    std::cerr << "cut_bag: cannot write " << relations_out << "\n";
    return false;
  }
  std::cout << "cut_bag: wrote " << relations_out << ": " << kept << " of " << total
            << " relations lie inside the slice\n";
  return true;
}

int cut(const Arguments& args) {
  rosbag::Bag input(args.input, rosbag::bagmode::Read);
  const std::vector<double> stamps = scanStamps(input, args.cut.scan_topic);
  if (stamps.empty()) {
    std::cerr << "cut_bag: no messages on " << args.cut.scan_topic << " in " << args.input << "\n";
    return 1;
  }
  const std::vector<double> selected = sliceStamps(stamps, args.cut);
  if (selected.empty()) {
    std::cerr << "cut_bag: the requested slice holds no scans\n";
    return 1;
  }
  const double first = selected.front(), last = selected.back();
  const CutCounts counts = copySlice(input, args.output, args.cut, first, last);
  std::cout << "cut_bag: wrote " << args.output << ": " << counts.scans << " scans (" << std::fixed
            << (last - first) << " s from stamp " << first << "), " << counts.odometry << " odometry, "
            << counts.tf << " tf, " << counts.tf_static << " tf_static messages\n";
  return args.relations.empty() || cutRelations(args, selected) ? 0 : 1;
}

}  // namespace
}  // namespace hglasm_odometry

int main(int argc, char** argv) {
  hglasm_odometry::Arguments args;
  const auto parsed = hglasm_odometry::parseArguments(argc, argv, &args);
  if (parsed != hglasm_odometry::ArgumentParser::Result::kOk) return hglasm_odometry::exitStatus(parsed);
  try {
    return hglasm_odometry::cut(args);
  } catch (const rosbag::BagException& ex) {
    std::cerr << "cut_bag: " << ex.what() << "\n";
    return 1;
  }
}
