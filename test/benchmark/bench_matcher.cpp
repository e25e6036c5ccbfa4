// Speed of the matcher on real scans (Google Benchmark, one thread). The papers' protocol: reference = odd
// beams of a real scan, new scan = even beams moved by a known initial position error inside the preset's
// box. One iteration = one match INCLUDING the reference preparation (lookup-table build + MbICP
// reference), as a live odometry pays it at every keyframe.
//
// Scans: the fixtures in test/data (fr079: 360 beams / 180 deg, intel: 180 beams, ccny: 681 beams / 239 deg),
// so this builds and runs in the ROS-free core-only mode too. Report medians:
//   bench_matcher --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Counter `success`: fraction of the timed matches within 0.10 m / 0.01 rad of the truth (a sanity check
// that the timed work is the real work).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "../core/test_util.h"
#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/mbicp.h"
#include "hglasm_odometry/core/scan_matcher.h"

namespace {

using hglasm::Pose2D;
using hglasm::Preset;
using hglasm::Scan;

/// One odd/even pair with its initial position error.
struct PairCase {
  Scan reference;  // odd beams
  Scan scan;       // even beams seen from `truth`
  Pose2D truth;
};

struct Dataset {
  std::string name;
  std::vector<Scan> scans;  // full scans, spread over the recording
};

Dataset loadDataset(const std::string& name, const std::string& file) {
  Dataset dataset{name, {}};
  double last_stamp = -1e300;
  for (const auto& real : hglasm_test::loadScanFixture(hglasm_test::fixturePath(file))) {
    if (real.stamp - last_stamp < 5.0) continue;  // skip the fixtures' block of consecutive scans
    last_stamp = real.stamp;
    Scan scan = hglasm::scanFromRanges(real.ranges);
    if (scan.size() >= 100) dataset.scans.push_back(scan);
  }
  return dataset;
}

/// Pairs with errors uniform in `fraction` of `box` (fixed seed: every run times the same work).
std::vector<PairCase> makeCases(const Dataset& dataset, const hglasm::SearchBox& box, double fraction,
                                int per_scan) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<PairCase> cases;
  for (const Scan& scan : dataset.scans) {
    const Scan odd = hglasm_test::beamsWithParity(scan, 1);
    const Scan even = hglasm_test::beamsWithParity(scan, 0);
    for (int k = 0; k < per_scan; ++k) {
      const Pose2D truth(fraction * box.half_x * unit(rng), fraction * box.half_y * unit(rng),
                         fraction * box.half_theta * unit(rng));
      cases.push_back({odd, hglasm_test::displacedScan(even, truth), truth});
    }
  }
  return cases;
}

bool success(const Pose2D& estimate, const Pose2D& truth) {
  return hglasm_test::translationError(estimate, truth) < 0.10 &&
         hglasm_test::rotationError(estimate, truth) < 0.01;
}

/// Times reference preparation + match from the identity over the pairs in turn (ScanMatcher or Mbicp),
/// and reports the share of matches that found the truth.
template <typename Matcher>
void timeMatches(benchmark::State& state, Matcher& matcher, const std::vector<PairCase>& cases) {
  std::size_t next = 0;
  std::int64_t successes = 0, matches = 0;
  for (auto _ : state) {
    const PairCase& pair = cases[next++ % cases.size()];
    matcher.setReference(pair.reference);
    const auto result = matcher.match(pair.scan, Pose2D());
    benchmark::DoNotOptimize(result.pose);
    // Tens of nanoseconds: cheaper than pausing the timer around it.
    successes += success(result.pose, pair.truth) ? 1 : 0;
    ++matches;
  }
  state.counters["success"] = matches ? static_cast<double>(successes) / matches : 0.0;
}

/// Full HGLASM-g match of a preset, reference preparation included.
void benchmarkMatch(benchmark::State& state, Preset preset, const std::vector<PairCase>& cases) {
  hglasm::ScanMatcher matcher(hglasm::presetOptions(preset));
  timeMatches(state, matcher, cases);
  state.counters["beams"] = cases.empty() ? 0.0 : cases.front().reference.beam_count;
}

/// The reference preparation alone, as ScanMatcher::setReference does it: the lookup table, the coarse
/// table when the preset uses one, and the MbICP reference.
void benchmarkSetReference(benchmark::State& state, Preset preset, const std::vector<PairCase>& cases) {
  hglasm::ScanMatcher matcher(hglasm::presetOptions(preset));
  std::size_t next = 0;
  for (auto _ : state) {
    matcher.setReference(cases[next++ % cases.size()].reference);
    benchmark::DoNotOptimize(matcher.table().tileCount());
  }
}

/// The graded lookup table build alone (the preset's table options).
void benchmarkTableBuild(benchmark::State& state, const std::vector<PairCase>& cases) {
  hglasm::LookupTable table(hglasm::presetOptions(Preset::kSmall).table);
  std::size_t next = 0;
  for (auto _ : state) {
    table.build(cases[next++ % cases.size()].reference.points);
    benchmark::DoNotOptimize(table.tileCount());
  }
  state.counters["tiles"] = static_cast<double>(table.tileCount());
  state.counters["bytes"] = static_cast<double>(table.memoryBytes());
}

/// MbICP alone from a small initial error (within its basin): reference preparation + match.
void benchmarkMbicp(benchmark::State& state, const std::vector<PairCase>& cases) {
  hglasm::Mbicp mbicp(hglasm::presetOptions(Preset::kSmall).mbicp);
  timeMatches(state, mbicp, cases);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  const std::vector<Dataset> datasets = {loadDataset("fr079_360", "fr079_scans.txt"),
                                         loadDataset("intel_180", "intel_scans.txt"),
                                         loadDataset("ccny_681", "ccny_scans.txt")};
  for (const Dataset& dataset : datasets) {
    if (dataset.scans.empty()) {
      std::fprintf(stderr, "no scans in the %s fixture (test/data); run test/data/extract_scans.py\n",
                   dataset.name.c_str());
      return 1;
    }
  }

  // The lambdas own copies of their cases: nothing global, nothing shared between benchmarks.
  for (const Dataset& dataset : datasets) {
    for (Preset preset : {Preset::kSmall, Preset::kMedium, Preset::kLarge}) {
      const auto cases = makeCases(dataset, hglasm::presetOptions(preset).genetic.box, 0.9, 8);
      benchmark::RegisterBenchmark(
          ("match/hglasm_g/" + std::string(hglasm::toString(preset)) + "/" + dataset.name).c_str(),
          [cases, preset](benchmark::State& state) { benchmarkMatch(state, preset, cases); })
          ->Unit(benchmark::kMillisecond);
    }
  }
  for (const Dataset& dataset : datasets) {
    const auto cases = makeCases(dataset, hglasm::presetOptions(Preset::kSmall).genetic.box, 0.9, 1);
    benchmark::RegisterBenchmark(("table_build/" + dataset.name).c_str(), [cases](benchmark::State& state) {
      benchmarkTableBuild(state, cases);
    })->Unit(benchmark::kMillisecond);
    for (Preset preset : {Preset::kSmall, Preset::kMedium, Preset::kLarge}) {
      benchmark::RegisterBenchmark(
          ("set_reference/" + std::string(hglasm::toString(preset)) + "/" + dataset.name).c_str(),
          [cases, preset](benchmark::State& state) { benchmarkSetReference(state, preset, cases); })
          ->Unit(benchmark::kMillisecond);
    }
  }
  for (const Dataset& dataset : datasets) {
    hglasm::SearchBox mbicp_box;  // within MbICP's basin: 5 cm, 3 degrees
    mbicp_box.half_x = mbicp_box.half_y = 0.05;
    mbicp_box.half_theta = hglasm_test::deg(3.0);
    const auto cases = makeCases(dataset, mbicp_box, 1.0, 8);
    benchmark::RegisterBenchmark(("match/mbicp_alone/" + dataset.name).c_str(), [cases](
                                                                                    benchmark::State& state) {
      benchmarkMbicp(state, cases);
    })->Unit(benchmark::kMillisecond);
  }

  benchmark::RunSpecifiedBenchmarks();  // no Shutdown(): Noetic's Google Benchmark 1.5.0 lacks it
  return 0;
}
