// evaluate's run and report on bags/fr079_slice.bag: the run is the nodelet's pipeline replayed pose for
// pose, its counts add up, thinning drops scans and keeps odometry, the wheel baseline and the direct
// pairs agree with the reference, and the report prints what the run found. Regressions on the other
// slices: intel's lever arm, fr-clinic's turn into a view the map lacks.
#include "hglasm_odometry/tools/evaluation_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "hglasm_odometry/evaluation/trajectory.h"
#include "hglasm_odometry/tools/evaluation_report.h"

namespace hglasm_odometry {
namespace {

const std::string kSource = HGLASM_SOURCE_DIR;

struct Slice {
  BagData data;
  std::vector<hglasm::Relation> relations;
  LaserOdometryOptions options;
};

const Slice& slice() {
  static const Slice loaded = [] {
    Slice s;
    std::string error;
    EXPECT_TRUE(readBag(kSource + "/bags/fr079_slice.bag", BagReadOptions(), &s.data, &error)) << error;
    EXPECT_TRUE(hglasm::readRelations(kSource + "/bags/fr079_slice.relations", &s.relations, &error))
        << error;
    EXPECT_TRUE(loadOptions(XmlRpc::XmlRpcValue(), &s.options, &error)) << error;
    return s;
  }();
  return loaded;
}

const EvaluationRun& run() {
  static const EvaluationRun result =
      runEvaluation(slice().data, slice().options, slice().options.tracker, 0.0);
  return result;
}

/// What `print` writes to a FILE*.
template <typename Print>
std::string printed(const Print& print) {
  char* buffer = nullptr;
  std::size_t size = 0;
  std::FILE* out = open_memstream(&buffer, &size);
  print(out);
  std::fclose(out);
  const std::string text(buffer, size);
  std::free(buffer);
  return text;
}

/// The nodelet's waits and queue of the slice's options.
ReplayOptions slicesReplay() {
  ReplayOptions replay;
  replay.odometry_wait = slice().options.odometry_wait;
  replay.queue_size = static_cast<std::size_t>(slice().options.queue_size);
  return replay;
}

/// The published poses of replaying `data` with `replay` through a pipeline of the slice's options.
std::vector<hglasm::StampedPose> replayed(const BagData& data, const ReplayOptions& replay) {
  hglasm::OdometryPipeline pipeline(slice().options.tracker, slice().options.odometry_wait > 0.0);
  setLaserMount(data, &pipeline);
  std::vector<hglasm::StampedPose> poses;
  replayBag(data, &pipeline, replay, [&poses](const ReplayedScan& scan) {
    if (scan.update.tracker.published) poses.push_back({scan.scan->stamp, scan.update.tracker.pose});
  });
  return poses;
}

TEST(EvaluationRun, IsTheNodeletsPipelineReplayed) {
  const std::vector<hglasm::StampedPose> expected = replayed(slice().data, slicesReplay());
  ASSERT_EQ(run().trajectory.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(run().trajectory[i].stamp, expected[i].stamp);
    EXPECT_EQ(run().trajectory[i].pose.x, expected[i].pose.x) << i;
    EXPECT_EQ(run().trajectory[i].pose.y, expected[i].pose.y) << i;
    EXPECT_EQ(run().trajectory[i].pose.theta, expected[i].pose.theta) << i;
  }
}

TEST(EvaluationRun, APacedReplayTakesTheBagsTimeOverItsRateAndMatchesTheSame) {
  BagData data = slice().data;
  data.arrivals.resize(60);
  const BagArrival& front = data.arrivals.front();
  const double first =
      front.scan ? data.scans[front.index].receive_time : data.odometry[front.index].receive_time;
  double last_scan = first;
  for (const BagArrival& arrival : data.arrivals) {
    if (arrival.scan) last_scan = std::max(last_scan, data.scans[arrival.index].receive_time);
  }
  ASSERT_GT(last_scan - first, 1.0);
  ReplayOptions replay = slicesReplay();
  const std::vector<hglasm::StampedPose> unpaced = replayed(data, replay);

  replay.pace_rate = (last_scan - first) / 0.3;  // the last scan 0.3 s of wall time after the first
  const auto start = std::chrono::steady_clock::now();
  const std::vector<hglasm::StampedPose> paced = replayed(data, replay);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(wall, 0.299);  // sleeping never ends early
  EXPECT_LT(wall, 10.0);   // nor lasts the rate squared
  ASSERT_EQ(paced.size(), unpaced.size());
  for (std::size_t i = 0; i < paced.size(); ++i) {
    EXPECT_EQ(paced[i].pose.x, unpaced[i].pose.x) << i;
    EXPECT_EQ(paced[i].pose.y, unpaced[i].pose.y) << i;
    EXPECT_EQ(paced[i].pose.theta, unpaced[i].pose.theta) << i;
  }
}

TEST(EvaluationRun, CountsAddUp) {
  const EvaluationRun& r = run();
  EXPECT_EQ(r.processed, slice().data.scans.size());
  EXPECT_EQ(r.updates.size(), r.trajectory.size());
  EXPECT_EQ(r.total_ms.size(), r.processed);
  EXPECT_EQ(r.prealign_ms.size(), static_cast<std::size_t>(r.matched));
  EXPECT_EQ(r.table_ms.size(), static_cast<std::size_t>(r.keyframes));
  int statuses = 0;
  for (const auto& entry : r.statuses) statuses += entry.second;
  EXPECT_EQ(statuses, r.matched);
  EXPECT_EQ(incrementCovariances(r).size(), r.trajectory.size());
  EXPECT_EQ(r.first_warnings.size(), std::min<std::size_t>(20, static_cast<std::size_t>(r.warnings)));
}

TEST(EvaluationRun, ThinningDropsScansAndKeepsTheOdometry) {
  const BagData& data = slice().data;
  std::size_t skipped = 0;
  const std::vector<BagArrival> kept = thinnedArrivals(data, 0.5, &skipped);
  std::size_t scans = 0, odometry = 0;
  for (const BagArrival& arrival : kept) (arrival.scan ? scans : odometry)++;
  EXPECT_EQ(odometry, data.odometry.size());
  EXPECT_EQ(scans + skipped, data.scans.size());
  EXPECT_GT(skipped, data.scans.size() / 2);  // 4.7 Hz thinned to at most 2 Hz
  const EvaluationRun thinned = runEvaluation(data, slice().options, slice().options.tracker, 0.5);
  EXPECT_EQ(thinned.skipped, skipped);
  EXPECT_EQ(thinned.processed, scans);
  // The relations are scored at every scan, the skipped ones at the pose interpolated between the
  // published ones around them, not left out (a run that drops scans must not drop its hard relations).
  ASSERT_EQ(thinned.trajectory.size(), scans);
  const double last_published = thinned.trajectory.back().stamp;
  int beyond = 0;  // relations that end after the last published pose: nothing to interpolate there
  for (const hglasm::Relation& relation : slice().relations) {
    beyond += std::max(relation.t1, relation.t2) > last_published + 1e-3;
  }
  const int missing = hglasm::evaluateRelations(slice().relations, thinned.trajectory, 0.0).missing;
  EXPECT_GT(missing, 10 * beyond);
  EXPECT_EQ(hglasm::evaluateRelations(slice().relations, thinned.scored, 0.0).missing, beyond);
  std::size_t within = 0;
  for (const BagScan& scan : data.scans) within += scan.stamp <= last_published;
  EXPECT_EQ(thinned.scored.size(), within) << "every scan up to the last published one";
  EXPECT_EQ(thinned.interpolated, within - scans);
  const hglasm::StampedPose& before = thinned.trajectory[0];
  const hglasm::StampedPose& after = thinned.trajectory[1];
  const hglasm::StampedPose& between = thinned.scored[1];
  ASSERT_GT(between.stamp, before.stamp);
  ASSERT_LT(between.stamp, after.stamp);
  const hglasm::Pose2D expected = hglasm::interpolate(
      before.pose, after.pose, (between.stamp - before.stamp) / (after.stamp - before.stamp));
  EXPECT_EQ(between.pose.x, expected.x);
  EXPECT_EQ(between.pose.theta, expected.theta);
}

TEST(EvaluationRun, WheelBaselineIsTheBagsOdometryAtTheScanStamps) {
  const BagData& data = slice().data;
  const std::vector<hglasm::StampedPose> wheel = wheelTrajectory(data);
  ASSERT_EQ(wheel.size(), data.scans.size());  // the slice's odometry covers its scans
  hglasm::OdometryBuffer buffer(1e9);
  for (const BagOdometry& sample : data.odometry) buffer.add(sample.stamp, sample.pose);
  hglasm::Pose2D later;
  ASSERT_TRUE(buffer.poseAt(data.scans[10].stamp + 0.2, 0.0, &later));
  const std::vector<hglasm::StampedPose> shifted = wheelTrajectory(data, 0.2);
  EXPECT_EQ(shifted[10].stamp, data.scans[10].stamp);
  EXPECT_EQ(shifted[10].pose.x, later.x);
}

TEST(EvaluationRun, DirectPairsAgreeWithTheReference) {
  std::vector<hglasm::Pose2D> motions;
  std::vector<bool> valid;
  directPairMotions(slice().options.tracker, slice().data, slice().relations, 10.0, &motions, &valid);
  const hglasm::RelationStats direct =
      hglasm::evaluateRelativeMotions(slice().relations, motions, valid, 10.0);
  EXPECT_GT(direct.count, 100);
  EXPECT_LT(direct.trans_mean, 0.05);
}

TEST(EvaluationReport, PrintsTheMetricAndTheSummaryOfTheRun) {
  const Slice& s = slice();
  const std::vector<hglasm::StampedPose> wheel = wheelTrajectory(s.data);
  const RelationsReport report = evaluateRun(s.relations, run(), wheel, s.data, 10.0);
  EXPECT_EQ(report.laser_all.count + report.laser_all.missing, static_cast<int>(s.relations.size()));
  EXPECT_TRUE(report.laser_frame);  // fr079's laser is 4 cm ahead of the base
  EXPECT_FALSE(report.has_direct_pairs);
  ASSERT_EQ(report.worst.size(), 5u);
  EXPECT_GE(report.worst[0].laser.trans(), report.worst[4].laser.trans());
  EXPECT_LT(report.laser_short.trans_mean, report.wheel_short.trans_mean * 2.0);

  const std::string text = printed([&](std::FILE* out) {
    printRelationsReport(out, "r.relations", s.relations, report, "base_link", true);
    printSummary(out, "medium", run(), report);
  });
  EXPECT_NE(text.find("relations     r.relations: 156 (Kümmerle"), std::string::npos) << text;
  EXPECT_NE(text.find("  laser frame (the same trajectories"), std::string::npos) << text;
  EXPECT_NE(text.find("SUMMARY preset=medium scans=" + std::to_string(run().processed) + " "),
            std::string::npos);
  char all[64];
  std::snprintf(all, sizeof all, " all_t=%.4f all_r=%.3f ", report.laser_all.trans_mean,
                report.laser_all.rot_mean_deg);
  EXPECT_NE(text.find(all), std::string::npos) << text;
}

TEST(EvaluationReport, TimesEachEstimateAgainstTheReferencesClockAndJudgesTheReference) {
  const Slice& s = slice();
  const std::vector<hglasm::StampedPose> wheel = wheelTrajectory(s.data);
  const RelationsReport report = evaluateRun(s.relations, run(), wheel, s.data, 10.0, &s.options.tracker);
  ASSERT_TRUE(report.has_timing);
  // fr079's wheels run about a tenth of a second behind the scans, which keep the reference's clock.
  EXPECT_GT(report.wheel_timing.count, 30);
  EXPECT_NEAR(report.wheel_timing.offset, 0.11, 0.04);
  EXPECT_LT(std::abs(report.laser_timing.offset), 0.02);
  EXPECT_LT(std::abs(report.direct_pairs_timing.offset), 0.02);
  // Nothing in this slice is contradicted by its scans and wheels together: the rest is everything.
  EXPECT_EQ(report.contradicted, 0);
  EXPECT_EQ(report.laser_short_uncontradicted.count, report.laser_short.count);
  EXPECT_DOUBLE_EQ(report.calibration_uncontradicted.mean_sq_mahalanobis,
                   report.calibration.mean_sq_mahalanobis);

  const std::string text = printed([&](std::FILE* out) {
    printRelationsReport(out, "r.relations", s.relations, report, "base_link", true);
    printSummary(out, "medium", run(), report);
  });
  EXPECT_NE(text.find("  timing <= 10 s: heading error = offset x change of turn rate"), std::string::npos)
      << text;
  EXPECT_NE(text.find("  contradicted: 0 relations <= 10 s"), std::string::npos) << text;
  char timing[96];
  std::snprintf(timing, sizeof timing, " wheel_timing_ms=%.1f turn_scale_pct=%.2f ",
                1e3 * report.wheel_timing.offset, 1e2 * report.laser_timing.turn_scale);
  EXPECT_NE(text.find(timing), std::string::npos) << text;
  // Where the laser sits against the mount: not learned by default (odometry/calibration/laser_offset 0).
  EXPECT_NE(text.find(" laser_offset_x=0.0000 laser_offset_y=0.0000\n"), std::string::npos) << text;
}

TEST(EvaluationReport, PrintsTheRunWithItsWarningsWhenAsked) {
  EvaluationRun r;
  r.processed = 4;
  r.matched = 3;
  r.total_ms = {1.0, 2.0, 3.0, 10.0};
  r.warnings = 1;
  r.first_warnings = {{12.5, "a warning"}};
  const std::string loud = printed([&](std::FILE* out) { printRun(out, r, 2.0, true); });
  EXPECT_EQ(loud.rfind("  warning at 12.500000: a warning\n", 0), 0u) << loud;
  EXPECT_NE(loud.find("\nscans         4 processed, 3 matched,"), std::string::npos) << loud;
  char total[128];  // median 2.5, nearest-rank p99 and max 10, mean 4
  std::snprintf(total, sizeof total, "  %-29s %6d %8.3f %8.3f %8.3f %8.3f\n", "total per scan (CPU)", 4, 2.5,
                10.0, 10.0, 4.0);
  EXPECT_NE(loud.find(total), std::string::npos) << loud;
  const std::string quiet = printed([&](std::FILE* out) { printRun(out, r, 2.0, false); });
  EXPECT_EQ(quiet.find("warning at"), std::string::npos);
}

TEST(EvaluationRun, WritesTheScanMap) {
  if (std::system("gnuplot --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "no gnuplot";
  const std::string png = testing::TempDir() + "hglasm_scan_map.png";
  std::string error;
  ASSERT_TRUE(writeScanMap(png, "slice", slice().data,
                           pipelineConversion(slice().options.tracker, slice().data), run().trajectory,
                           wheelTrajectory(slice().data), &error))
      << error;
  std::FILE* file = std::fopen(png.c_str(), "r");
  EXPECT_NE(file, nullptr) << png;
  if (file) std::fclose(file);
  std::remove(png.c_str());
}

TEST(EvaluationRun, LearnsWhereIntelsLaserSitsAsTheWholeLogDoes) {
  // intel's bag puts the laser at the base origin; over the whole log (13631 scans) its turns against the
  // wheels put it 0.100 m ahead (doc/accuracy.md, "The laser's lever arm"). The slice's 600 scans agree.
  BagData data;
  std::string error;
  ASSERT_TRUE(readBag(kSource + "/bags/intel_slice.bag", BagReadOptions(), &data, &error)) << error;
  LaserOdometryOptions options;
  ASSERT_TRUE(loadOptions(XmlRpc::XmlRpcValue(), &options, &error)) << error;
  EXPECT_EQ(options.tracker.learning.wheel_calibration.laser_offset, 0.0) << "tf's mount by default";
  options.tracker.learning.wheel_calibration.laser_offset = 0.1;
  const EvaluationRun learned = runEvaluation(data, options, options.tracker, 0.0);
  ASSERT_FALSE(learned.updates.empty());
  const Eigen::Vector2d offset = learned.updates.back().diagnostics.learned.laser_offset;
  EXPECT_GT(offset.x(), 0.07);
  EXPECT_LT(offset.x(), 0.14);
  EXPECT_LT(std::abs(offset.y()), 0.02);
}

TEST(EvaluationRun, FrClinicsTurnIntoAViewTheMapLacksMostlyKeepsTheWheels) {
  // bags/fr-clinic_turn_slice.bag: near its end (1232660475-481 s) the robot turns 90 degrees into a view
  // its local map lacks; scans fit it ever worse near the wheels' excellent prediction and some 0.4-0.9 m
  // away better, and the next scan of the same view asks for the same wrong correction. Over GA seeds 1-10
  // the previous release leapt there 9 times (largest leap ratio 1.05-1.83, mean 1.56); a deferred leap
  // that fits nowhere as usual now counts as unexplained and the map restarts on the wheels (4 leaps of
  // 1.05-1.83, mean 0.76; 0.73 since a scan after a leap joins the map only once it fits as usual).
  BagData data;
  std::vector<hglasm::Relation> relations;
  std::string error;
  ASSERT_TRUE(readBag(kSource + "/bags/fr-clinic_turn_slice.bag", BagReadOptions(), &data, &error)) << error;
  ASSERT_TRUE(hglasm::readRelations(kSource + "/bags/fr-clinic_turn_slice.relations", &relations, &error))
      << error;
  LaserOdometryOptions options;
  ASSERT_TRUE(loadOptions(XmlRpc::XmlRpcValue(), &options, &error)) << error;
  const std::vector<hglasm::StampedPose> wheel = wheelTrajectory(data);
  double sum = 0.0;
  const int seeds = 10;
  for (int seed = 1; seed <= seeds; ++seed) {
    options.tracker.matcher.genetic.seed = seed;
    const RelationsReport report =
        evaluateRun(relations, runEvaluation(data, options, options.tracker, 0.0), wheel, data, 10.0);
    ASSERT_GT(report.laser_short.count, 100);
    std::printf("[measured] seed %d: largest leap ratio %.3f (%.3f +%.2f s: %.3f m, wheels %.3f m)\n", seed,
                report.worst_leap_ratio, report.worst_leap.t1, report.worst_leap.span,
                report.worst_leap.laser.trans(), report.worst_leap.wheel.trans());
    sum += report.worst_leap_ratio;
  }
  EXPECT_LT(sum / seeds, 1.0) << "the mean over the seeds of the largest laser / (3 x wheels' + 0.10 m)";
}

}  // namespace
}  // namespace hglasm_odometry
