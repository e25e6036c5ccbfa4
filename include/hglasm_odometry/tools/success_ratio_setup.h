// The success_ratio tool's pieces: its command line into the protocol's options, the scans it reads (a bag
// or a CARMEN log), and the CSVs and plots it writes. The protocol itself is evaluation/success_ratio.h.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/evaluation/success_ratio.h"
#include "hglasm_odometry/tools/argument_parser.h"
#include "hglasm_odometry/tools/bag_reader.h"

namespace hglasm_odometry {

struct SuccessRatioArguments {
  std::string bag;
  std::string topic = "/scan";
  bool topic_given = false;
  std::string carmen;
  int trials = 0;  // 0: not given
  std::uint64_t seed = 0;
  bool seed_given = false;
  std::string csv;
  std::string plots;
  std::string algorithms = "hglasm_g,hglasm_binary,glasm_g,glasm_binary,mbicp,pga,hpga";
  std::string curve_algorithms = "glasm_g,glasm_binary,pga";
  std::string time_csv;
  bool ceiling = true;
  double interlace_seconds = 0.0;
  std::string presets = "small,medium,large";
  std::string cases = "paper";
  bool in_box = false;
  int curve_trials = -1;  // -1: same as trials
  std::string curve_generations;
  std::string curve_csv;
  std::size_t max_scans = 0;
  int min_points = 40;
  BeamAngleOverrides beam_angles;
  std::string title;
  bool quiet = false;
};

/// kOk with *args and *options filled and checked across options, or what the tool should exit with (the
/// usage or the problem printed).
ArgumentParser::Result parseSuccessRatioArguments(const std::vector<std::string>& arguments,
                                                  SuccessRatioArguments* args,
                                                  hglasm::SuccessRatioOptions* options);

/// The base's velocity (vx, vy, omega in its own frame) at `stamp`: the wheel odometry's motion between
/// the samples around it (the first or last two beyond them); zero with fewer than two samples.
Eigen::Vector3d baseVelocityAt(const std::vector<BagOdometry>& odometry, double stamp);

/// The scans (with the arguments' beam-angle overrides) and, with --interlace-seconds, each scan's offset
/// of its odd beams from its even ones (halfScanOffset); what was read goes to `log`.
bool readSuccessRatioScans(const SuccessRatioArguments& args, std::vector<hglasm::RangeScan>* scans,
                           std::vector<hglasm::Pose2D>* half_offsets, std::ostream& log, std::string* error);

/// `csv` with `tail` (e.g. "_evaluations.csv") in place of its ".csv".
std::string siblingCsv(const std::string& csv, const std::string& tail);

/// Fails now on outputs that cannot be written rather than after a long run: the CSV, the plot directory
/// (created).
bool prepareSuccessRatioOutputs(const SuccessRatioArguments& args, std::string* error);

/// The result CSV, the curve and time-to-reach CSVs (when there are curves) and the plots (with --plots).
bool writeSuccessRatioOutputs(const SuccessRatioArguments& args, const hglasm::SuccessRatioReport& report,
                              std::ostream& log, std::string* error);

}  // namespace hglasm_odometry
