// success_ratio: the papers' Success-Ratio experiment on real scans from a bag or a CARMEN log. The
// protocol is evaluation/success_ratio.h, the arguments, reading and writing tools/success_ratio_setup.h;
// this main runs them and prints progress on stderr.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "hglasm_odometry/tools/success_ratio_setup.h"

namespace {

constexpr int kExitRuntimeError = 1;

int failRuntime(const std::string& message) {
  std::cerr << "success_ratio: error: " << message << "\n";
  return kExitRuntimeError;
}

}  // namespace

int main(int argc, char** argv) {
  hglasm_odometry::SuccessRatioArguments args;
  hglasm::SuccessRatioOptions options;
  const auto parsed = hglasm_odometry::parseSuccessRatioArguments(
      std::vector<std::string>(argv + 1, argv + argc), &args, &options);
  if (parsed != hglasm_odometry::ArgumentParser::Result::kOk) return hglasm_odometry::exitStatus(parsed);
  std::string error;
  if (!hglasm_odometry::prepareSuccessRatioOutputs(args, &error)) return failRuntime(error);
  std::vector<hglasm::RangeScan> scans;
  if (!hglasm_odometry::readSuccessRatioScans(args, &scans, &options.half_offsets, std::cerr, &error)) {
    return failRuntime(error);
  }

  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&start]() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const auto progress = [&](const hglasm::SuccessRatioProgress& state) {
    if (args.quiet) return;
    char prefix[64];
    std::snprintf(prefix, sizeof(prefix), "[%4zu/%-4zu %6.0fs] ", state.cells_done, state.cells_total,
                  elapsed());
    std::cerr << prefix << state.message << "\n";
  };
  std::cerr << "success_ratio: " << options.algorithms.size() << " algorithm(s) x " << options.presets.size()
            << " preset(s) x " << options.cases.size() << " case(s)" << (options.in_box ? " + in-box" : "")
            << ", " << options.trials << " trials each, seed " << options.seed
            << (options.curve_trials > 0 ? ", curves " + std::to_string(options.curve_trials) + " trials"
                                         : "")
            << "\n";
  hglasm::SuccessRatioReport report;
  if (!hglasm::runSuccessRatio(scans, options, &report, &error, progress)) return failRuntime(error);
  std::cerr << "success_ratio: " << report.scans_used << " of " << report.scans_total << " scans usable, "
            << report.scans_skipped << " skipped (fewer than " << options.min_points_per_half
            << " valid points in the odd or even beams); " << report.rows.size() << " rows in " << elapsed()
            << " s\n";
  if (!hglasm_odometry::writeSuccessRatioOutputs(args, report, std::cerr, &error)) return failRuntime(error);
  return 0;
}
