// Speed of each stage of the per-scan pipeline on real scans (Google Benchmark, one thread), so a change to
// one stage is measured on that stage alone (issue 22). The fixtures in test/data: the spread scans of fr079
// (360 beams), intel (180) and ccny (681) for the single-scan stages, and the 20 consecutive scans of fr079
// and intel (with their recorded wheel odometry) for the sequence stages. Report medians:
//   bench_stages --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Every benchmark checks that the timed work is the real work: a DoNotOptimize on its result and a counter
// (`points`, `tiles`, `success`: the share of matches within 0.10 m / 0.01 rad of the truth, `matched`: the
// share of the sequence's scans the tracker matched; MbICP's mean `iterations` too, since a cheaper
// association that costs iterations is no gain). Sequence benchmarks time one pass over the block per
// iteration (a fresh map or pipeline, made with the timer paused) and count its scans or keyframes as
// items: CPU time per scan or keyframe = 1 / items_per_second. Only what Google Benchmark 1.5.0 (Ubuntu
// 20.04) has: no Counter::kInvert, no benchmark::Shutdown().
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "../core/test_util.h"
#include "hglasm_odometry/core/genetic_aligner.h"
#include "hglasm_odometry/core/local_map.h"
#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/mbicp.h"
#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/core/search_sizing.h"

namespace {

using hglasm::Pose2D;
using hglasm::Preset;
using hglasm::Scan;
using hglasm_test::RealScan;

struct Fixture {
  std::string name;
  std::vector<RealScan> spread;       // scans seconds to minutes apart
  std::vector<RealScan> consecutive;  // the block of consecutive scans (empty for ccny)
  Pose2D mount;                       // base_link to laser
};

Fixture loadFixture(const std::string& name, const std::string& file, const Pose2D& mount) {
  Fixture fixture{name, {}, {}, mount};
  const std::vector<RealScan> reals = hglasm_test::loadScanFixture(hglasm_test::fixturePath(file));
  // A scan within a second of its neighbour belongs to the consecutive block; the others are spread.
  for (std::size_t i = 0; i < reals.size(); ++i) {
    const bool after = i > 0 && reals[i].stamp - reals[i - 1].stamp < 1.0;
    const bool before = i + 1 < reals.size() && reals[i + 1].stamp - reals[i].stamp < 1.0;
    (after || before ? fixture.consecutive : fixture.spread).push_back(reals[i]);
  }
  return fixture;
}

std::vector<Scan> convertAll(const std::vector<RealScan>& reals) {
  std::vector<Scan> scans;
  for (const RealScan& real : reals) scans.push_back(hglasm::scanFromRanges(real.ranges));
  return scans;
}

/// A reference (odd beams), a scan (even beams) moved by a known error, for the GA and MbICP alone.
struct PairCase {
  Scan reference;
  Scan scan;
  Pose2D truth;
};

std::vector<PairCase> makeCases(const std::vector<Scan>& scans, const hglasm::SearchBox& box, int per_scan) {
  std::mt19937 rng(2024);  // fixed: every run times the same work
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<PairCase> cases;
  for (const Scan& scan : scans) {
    if (scan.size() < 100) continue;
    const Scan even = hglasm_test::beamsWithParity(scan, 0);
    for (int k = 0; k < per_scan; ++k) {
      const Pose2D truth(box.half_x * unit(rng), box.half_y * unit(rng), box.half_theta * unit(rng));
      cases.push_back(
          {hglasm_test::beamsWithParity(scan, 1), hglasm_test::displacedScan(even, truth), truth});
    }
  }
  return cases;
}

bool success(const Pose2D& estimate, const Pose2D& truth) {
  return hglasm_test::translationError(estimate, truth) < 0.10 &&
         hglasm_test::rotationError(estimate, truth) < 0.01;
}

// ------------------------------------------------------------------------------------------ the stages

/// RangeScan -> Scan: range limits, invalid beams dropped, beam angles (the default conversion).
void benchmarkConversion(benchmark::State& state, const std::vector<RealScan>& reals) {
  std::size_t next = 0, points = 0, scans = 0;
  for (auto _ : state) {
    const Scan scan = hglasm::scanFromRanges(reals[next++ % reals.size()].ranges);
    benchmark::DoNotOptimize(scan.points.data());
    points += scan.size();
    ++scans;
  }
  state.counters["points"] = scans ? static_cast<double>(points) / scans : 0.0;
}

/// Motion compensation of a converted scan at a constant velocity (0.5 m/s, 0.5 rad/s).
void benchmarkDeskew(benchmark::State& state, const std::vector<Scan>& scans) {
  std::size_t next = 0, points = 0, runs = 0;
  for (auto _ : state) {
    Scan scan = scans[next++ % scans.size()];
    scan.time_increment = 1.0 / 40.0 / scan.beam_count;  // 40 Hz sweep
    const Scan moved = hglasm::deskewScan(scan, Eigen::Vector3d(0.5, 0.0, 0.5));
    benchmark::DoNotOptimize(moved.points.data());
    points += moved.size();
    ++runs;
  }
  state.counters["points"] = runs ? static_cast<double>(points) / runs : 0.0;
}

/// A lookup table built from scratch on one whole scan (`table`: the fine or the coarse table's options).
void benchmarkTableBuild(benchmark::State& state, const hglasm::LookupTableOptions& table_options,
                         const std::vector<Scan>& scans) {
  hglasm::LookupTable table(table_options);
  std::size_t next = 0;
  for (auto _ : state) {
    table.build(scans[next++ % scans.size()].points);
    benchmark::DoNotOptimize(table.tileCount());
  }
  state.counters["tiles"] = static_cast<double>(table.tileCount());
}

/// The keyframe insertion of OdometryTracker::addKeyframe over the consecutive block (every scan a keyframe
/// at its wheel pose): the local map's de-duplication, both tables grown, and MbICP's reference extended
/// (`reframe_distance` 1 m, the default) or rebuilt at every keyframe (`reframe_distance` 0).
void benchmarkKeyframes(benchmark::State& state, const Fixture& fixture, double reframe_distance) {
  const hglasm::TrackerOptions defaults;
  hglasm::LocalMapOptions map_options = defaults.local_map;
  map_options.reframe_distance = reframe_distance;
  const std::vector<Scan> scans = convertAll(fixture.consecutive);
  std::optional<hglasm::LocalMap> map;
  hglasm::ScanMatcher matcher(defaults.matcher);
  std::size_t reference_points = 0;
  for (auto _ : state) {
    state.PauseTiming();
    map.emplace(map_options, std::vector<hglasm::LookupTableOptions>{defaults.matcher.table,
                                                                     defaults.matcher.coarse_table});
    state.ResumeTiming();
    for (std::size_t i = 0; i < scans.size(); ++i) {
      map->add(fixture.consecutive[i].odometry * fixture.mount, scans[i].points);
      matcher.useTables(&map->table(0), &map->table(1));
      matcher.extendReference(map->reference(), map->unchangedScans());
    }
    benchmark::DoNotOptimize(matcher.hasReference());
    reference_points = map->reference().size();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(scans.size()));  // keyframes
  state.counters["points"] = static_cast<double>(reference_points);
}

/// The GA alone (fine table, coarse table when the effort uses it) on prepared tables, from the identity.
void benchmarkGenetic(benchmark::State& state, const hglasm::SearchEffort& effort,
                      const std::vector<PairCase>& cases) {
  const hglasm::MatcherOptions options;
  std::vector<hglasm::LookupTable> fine, coarse;
  for (const PairCase& pair : cases) {
    fine.emplace_back(options.table).build(pair.reference.points);
    coarse.emplace_back(options.coarse_table).build(pair.reference.points);
  }
  hglasm::GeneticAligner aligner(options.genetic);
  std::size_t next = 0;
  std::int64_t successes = 0, runs = 0;
  for (auto _ : state) {
    const std::size_t k = next++ % cases.size();
    const auto result = aligner.align(fine[k], cases[k].scan.points, Pose2D(), nullptr, &coarse[k], &effort);
    benchmark::DoNotOptimize(result.pose);
    successes += success(result.pose, cases[k].truth) ? 1 : 0;
    ++runs;
  }
  state.counters["success"] = runs ? static_cast<double>(successes) / runs : 0.0;
}

/// MbICP alone on prepared references, from a start within its basin.
void benchmarkMbicp(benchmark::State& state, const std::vector<PairCase>& cases) {
  std::vector<hglasm::Mbicp> mbicps(cases.size(), hglasm::Mbicp(hglasm::MatcherOptions().mbicp));
  for (std::size_t k = 0; k < cases.size(); ++k) mbicps[k].setReference(cases[k].reference);
  std::size_t next = 0;
  std::int64_t successes = 0, runs = 0, iterations = 0;
  for (auto _ : state) {
    const std::size_t k = next++ % cases.size();
    const auto result = mbicps[k].match(cases[k].scan, Pose2D());
    benchmark::DoNotOptimize(result.pose);
    successes += success(result.pose, cases[k].truth) ? 1 : 0;
    iterations += result.iterations;
    ++runs;
  }
  state.counters["success"] = runs ? static_cast<double>(successes) / runs : 0.0;
  state.counters["iterations"] = runs ? static_cast<double>(iterations) / runs : 0.0;
}

/// The whole per-scan update (conversion, prediction, search sizing, GA, MbICP, fusion, keyframes) of a fresh
/// OdometryPipeline (default options) over the consecutive block, the wheels a sample at each scan's stamp.
void benchmarkPipeline(benchmark::State& state, const Fixture& fixture) {
  std::optional<hglasm::OdometryPipeline> pipeline;
  std::int64_t matched = 0, updates = 0;
  for (auto _ : state) {
    state.PauseTiming();
    pipeline.emplace(hglasm::TrackerOptions());
    pipeline->setLaserMount(fixture.mount, false);
    state.ResumeTiming();
    for (const RealScan& real : fixture.consecutive) {
      pipeline->addOdometry(real.stamp, real.odometry);
      const auto update = pipeline->processScan(real.stamp, real.ranges);
      benchmark::DoNotOptimize(update.tracker.pose);
      matched += update.tracker.matched && !update.tracker.fallback ? 1 : 0;
      updates += update.tracker.matched ? 1 : 0;
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(fixture.consecutive.size()));
  state.counters["matched"] = updates ? static_cast<double>(matched) / updates : 0.0;
}

// ------------------------------------------------------------------------------------------ registration

template <typename F>
void add(const std::string& name, F&& run) {
  benchmark::RegisterBenchmark(name.c_str(), std::forward<F>(run))->Unit(benchmark::kMicrosecond);
}

void registerSingleScanStages(const Fixture& fixture) {
  const std::vector<RealScan> reals = fixture.spread;
  const std::vector<Scan> scans = convertAll(reals);
  const hglasm::MatcherOptions matcher;
  add("convert/" + fixture.name, [reals](benchmark::State& s) { benchmarkConversion(s, reals); });
  add("deskew/" + fixture.name, [scans](benchmark::State& s) { benchmarkDeskew(s, scans); });
  add("table_build/fine/" + fixture.name,
      [scans, matcher](benchmark::State& s) { benchmarkTableBuild(s, matcher.table, scans); });
  add("table_build/coarse/" + fixture.name,
      [scans, matcher](benchmark::State& s) { benchmarkTableBuild(s, matcher.coarse_table, scans); });

  // The usual case with wheels: the smallest box searchAround gives (min_xy, min_theta), its GA size.
  const hglasm::SearchEffort tight =
      hglasm::searchAround(matcher.genetic, hglasm::SearchOptions(), Eigen::Matrix3d::Identity() * 1e-8);
  const hglasm::SearchEffort small = hglasm::effortOf(hglasm::presetOptions(Preset::kSmall).genetic);
  const auto tight_cases = makeCases(scans, tight.box, 4);
  const auto small_cases = makeCases(scans, small.box, 4);
  add("ga/tight/" + fixture.name,
      [tight, tight_cases](benchmark::State& s) { benchmarkGenetic(s, tight, tight_cases); });
  add("ga/small/" + fixture.name,
      [small, small_cases](benchmark::State& s) { benchmarkGenetic(s, small, small_cases); });
  hglasm::SearchBox near;  // within MbICP's basin: 5 cm, 3 degrees
  near.half_x = near.half_y = 0.05;
  near.half_theta = hglasm_test::deg(3.0);
  const auto near_cases = makeCases(scans, near, 4);
  add("mbicp/" + fixture.name, [near_cases](benchmark::State& s) { benchmarkMbicp(s, near_cases); });
}

void registerSequenceStages(const Fixture& fixture) {
  if (fixture.consecutive.size() < 2 || !fixture.consecutive.front().has_odometry) return;
  add("keyframes/extend/" + fixture.name,
      [fixture](benchmark::State& s) { benchmarkKeyframes(s, fixture, 1.0); });
  add("keyframes/rebuild/" + fixture.name,
      [fixture](benchmark::State& s) { benchmarkKeyframes(s, fixture, 0.0); });
  add("pipeline/" + fixture.name, [fixture](benchmark::State& s) { benchmarkPipeline(s, fixture); });
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // fr079's laser is 0.04 m ahead of base_link; intel's at its origin (test/data/README.md).
  const std::vector<Fixture> fixtures = {loadFixture("fr079_360", "fr079_scans.txt", Pose2D(0.04, 0.0, 0.0)),
                                         loadFixture("intel_180", "intel_scans.txt", Pose2D()),
                                         loadFixture("ccny_681", "ccny_scans.txt", Pose2D())};
  for (const Fixture& fixture : fixtures) {
    if (fixture.spread.empty()) {
      std::fprintf(stderr, "no scans in the %s fixture (test/data); run test/data/extract_scans.py\n",
                   fixture.name.c_str());
      return 1;
    }
  }
  for (const Fixture& fixture : fixtures) registerSingleScanStages(fixture);
  for (const Fixture& fixture : fixtures) registerSequenceStages(fixture);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
