// evaluate: runs the nodelet's odometry pipeline (hglasm::OdometryPipeline, same options and YAML) over a
// bag as fast as the CPU allows, without a ROS master, and scores it on the Kümmerle et al. relations
// benchmark next to the bag's raw wheel odometry. The pieces live in the tools and evaluation libraries.
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "hglasm_odometry/evaluation/trajectory.h"
#include "hglasm_odometry/tools/evaluate_setup.h"
#include "hglasm_odometry/tools/evaluation_report.h"
#include "hglasm_odometry/tools/evaluation_run.h"

namespace hglasm_odometry {
namespace {

int fail(const std::string& message, int status) {
  std::cerr << "evaluate: " << message << "\n";
  return status;
}

/// --out, --trace, --plot and --map, each if asked for.
int writeOutputs(const EvaluateArguments& args, const std::string& preset,
                 const hglasm::TrackerOptions& options, const BagData& data, const EvaluationRun& run,
                 const std::vector<hglasm::StampedPose>& wheel) {
  const std::vector<Eigen::Matrix3d> covariances = incrementCovariances(run);
  if (!args.out.empty() && !hglasm::writeTrajectory(args.out, run.trajectory, &covariances)) {
    return fail("cannot write " + args.out, 1);
  }
  if (!args.out.empty())
    std::printf("trajectory    %s (%zu poses)\n", args.out.c_str(), run.trajectory.size());
  if (!args.trace.empty() && !hglasm::writeTrackerTrace(args.trace, run.updates)) {
    return fail("cannot write " + args.trace, 1);
  }
  if (!args.trace.empty()) std::printf("trace         %s\n", args.trace.c_str());
  const std::string title = args.bag.substr(args.bag.find_last_of('/') + 1) + ", preset " + preset;
  std::string error;
  if (!args.plot.empty() && !hglasm::plotTrajectories(args.plot, title, run.trajectory, wheel, &error)) {
    return fail(error, 1);
  }
  if (!args.plot.empty()) std::printf("plot          %s\n", args.plot.c_str());
  if (!args.map.empty() && !writeScanMap(args.map, title + ": scans at the laser poses", data,
                                         pipelineConversion(options, data), run.trajectory, wheel, &error)) {
    return fail(error, 1);
  }
  if (!args.map.empty()) std::printf("map           %s\n", args.map.c_str());
  return 0;
}

int evaluate(const EvaluateArguments& args) {
  std::string error;
  LaserOdometryOptions nodelet;  // the nodelet's options, through the nodelet's own loader
  std::vector<std::string> warnings;
  bool config_found = false;
  if (!loadEvaluateOptions(args, &nodelet, &warnings, &config_found, &error)) return fail(error, 2);
  if (!config_found) std::printf("config        %s not found: built-in defaults\n", args.config.c_str());
  for (const auto& warning : warnings) std::printf("config        warning: %s\n", warning.c_str());
  hglasm::TrackerOptions options = nodelet.tracker;
  if (!args.use_odometry) options.prediction.use_odometry = false;

  EvaluateInputs inputs;
  if (!readEvaluateInputs(args, nodelet.base_frame, &inputs, &error)) return fail(error, 1);
  const BagData& data = inputs.data;
  printInputs(stdout, args, inputs, nodelet.preset, options.prediction.use_odometry);
  const EvaluationRun run = runEvaluation(data, nodelet, options, args.min_scan_interval, args.pace_rate);
  printRun(stdout, run, data.scans.back().stamp - data.scans.front().stamp, !args.quiet);

  const std::vector<hglasm::StampedPose> wheel = wheelTrajectory(data, args.odom_stamp_shift);
  if (!inputs.relations.empty()) {
    const RelationsReport report = evaluateRun(inputs.relations, run, wheel, data, args.short_span,
                                               args.direct_pairs ? &options : nullptr);
    printRelationsReport(stdout, args.relations, inputs.relations, report, data.base_frame, !wheel.empty());
    printSummary(stdout, nodelet.preset, run, report);
    if (args.blend_wheels && !wheel.empty()) {
      printWheelBlends(stdout, inputs.relations, run.scored, wheel, args.short_span);
    }
    if (!args.relation_errors.empty()) {
      if (!hglasm::writeRelationErrors(args.relation_errors, inputs.relations, run.scored, wheel)) {
        return fail("cannot write " + args.relation_errors, 1);
      }
      std::printf("relations     per-relation errors in %s\n", args.relation_errors.c_str());
    }
  }
  return writeOutputs(args, nodelet.preset, options, data, run, wheel);
}

}  // namespace
}  // namespace hglasm_odometry

int main(int argc, char** argv) {
  hglasm_odometry::EvaluateArguments args;
  const auto parsed =
      hglasm_odometry::parseEvaluateArguments(std::vector<std::string>(argv + 1, argv + argc), &args);
  if (parsed != hglasm_odometry::ArgumentParser::Result::kOk) return hglasm_odometry::exitStatus(parsed);
  std::string error;
  if (!args.config_given && !hglasm_odometry::defaultConfigPath(&args.config, &error)) {
    std::cerr << "evaluate: " << error << "\n";
    return 2;
  }
  return hglasm_odometry::evaluate(args);
}
