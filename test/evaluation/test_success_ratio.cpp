// The Success-Ratio protocol and its CSV / plot output on simulated scans, where every answer is known
// exactly.
#include "hglasm_odometry/evaluation/success_ratio_report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../core/test_util.h"

namespace hglasm {
namespace {

using hglasm_test::deg;

/// Scans of the simulated room from a few poses inside it (0.5-degree, 180-degree laser).
std::vector<RangeScan> roomScans() {
  const hglasm_test::World world = hglasm_test::room();
  const hglasm_test::LaserSpec laser = hglasm_test::halfCircleLaser();
  std::vector<RangeScan> scans;
  for (const Pose2D& pose : {hglasm_test::rawPose(0.0, 0.0, 0.0), hglasm_test::rawPose(0.5, -0.3, 0.8),
                             hglasm_test::rawPose(-0.8, 0.4, 2.5), hglasm_test::rawPose(1.2, 0.6, -1.9)}) {
    scans.push_back(hglasm_test::simulateRanges(world, pose, laser));
  }
  return scans;
}

SuccessRatioOptions baseOptions() {
  SuccessRatioOptions options;
  options.algorithms = {Algorithm::kMbicp};
  options.presets = {Preset::kSmall};
  options.trials = 20;
  options.seed = 7;
  return options;
}

SuccessRatioReport run(const std::vector<RangeScan>& scans, const SuccessRatioOptions& options) {
  SuccessRatioReport report;
  std::string error;
  EXPECT_TRUE(runSuccessRatio(scans, options, &report, &error)) << error;
  return report;
}

/// CSV lines of the rows without the timing column mean_ms (the only field that varies between runs).
std::vector<std::string> linesWithoutTime(const SuccessRatioReport& report) {
  std::vector<std::string> lines;
  for (const SuccessRatioRow& row : report.rows) {
    const std::string line = successRatioCsvLine(row);
    const std::size_t ceiling = line.rfind(',');
    const std::size_t time = line.rfind(',', ceiling - 1);
    lines.push_back(line.substr(0, time) + line.substr(ceiling));
  }
  return lines;
}

TEST(SuccessRatioCases, PaperSweepCoversTheHeadlineCase) {
  const std::vector<IpeCase> cases = paperCases();
  EXPECT_EQ(cases.size(), 13u * 4u);
  bool headline = false;
  double max_rotation = 0.0, max_translation = 0.0;
  for (const IpeCase& ipe : cases) {
    headline = headline || (ipe.rotation_deg == 20.0 && ipe.translation_m == 0.57);
    max_rotation = std::max(max_rotation, ipe.rotation_deg);
    max_translation = std::max(max_translation, ipe.translation_m);
  }
  EXPECT_TRUE(headline);
  EXPECT_EQ(max_rotation, 180.0);
  EXPECT_EQ(max_translation, 2.12);
}

TEST(SuccessRatioCases, ParsesListsAndRejectsBadOnes) {
  std::vector<IpeCase> cases;
  std::string error;
  ASSERT_TRUE(parseCases("20:0.57,90:1.13,0:0", &cases, &error)) << error;
  ASSERT_EQ(cases.size(), 3u);
  EXPECT_EQ(cases[0].rotation_deg, 20.0);
  EXPECT_EQ(cases[0].translation_m, 0.57);
  EXPECT_EQ(cases[1].rotation_deg, 90.0);
  EXPECT_EQ(cases[2].translation_m, 0.0);
  ASSERT_TRUE(parseCases("paper", &cases, &error));
  EXPECT_EQ(cases.size(), paperCases().size());
  ASSERT_TRUE(parseCases("none", &cases, &error));
  EXPECT_TRUE(cases.empty());
  for (const char* bad : {"", "20", "20:", ":0.5", "abc:1", "20:0.5x", "181:1", "-1:0.5", "20:-0.1",
                          "20:0.5,,", "nan:1", "20:inf"}) {
    error.clear();
    EXPECT_FALSE(parseCases(bad, &cases, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
}

TEST(SuccessRatioCases, TrialErrorsHaveExactMagnitudesAndRandomDirections) {
  const IpeCase ipe{20.0, 0.57};
  std::set<std::size_t> picks;
  int negative = 0;
  double min_direction = 10.0, max_direction = -10.0;
  for (int trial = 0; trial < 200; ++trial) {
    std::size_t pick = 99;
    const Pose2D error = caseTrialError(ipe, 3, trial, 5, &pick);
    EXPECT_NEAR(std::hypot(error.x, error.y), 0.57, 1e-12);
    EXPECT_NEAR(std::abs(error.theta), deg(20.0), 1e-12);
    EXPECT_LT(pick, 5u);
    picks.insert(pick);
    negative += error.theta < 0 ? 1 : 0;
    const double direction = std::atan2(error.y, error.x);
    min_direction = std::min(min_direction, direction);
    max_direction = std::max(max_direction, direction);
    // Deterministic: the same (case, seed, trial) gives the same error and scan.
    std::size_t again = 99;
    const Pose2D repeat = caseTrialError(ipe, 3, trial, 5, &again);
    EXPECT_EQ(repeat.x, error.x);
    EXPECT_EQ(repeat.theta, error.theta);
    EXPECT_EQ(again, pick);
  }
  EXPECT_EQ(picks.size(), 5u);
  EXPECT_GT(negative, 60);
  EXPECT_LT(negative, 140);
  EXPECT_LT(min_direction, -2.5);
  EXPECT_GT(max_direction, 2.5);
  // Another seed draws other trials.
  const Pose2D other = caseTrialError(ipe, 4, 0, 5, nullptr);
  const Pose2D first = caseTrialError(ipe, 3, 0, 5, nullptr);
  EXPECT_NE(other.x, first.x);
}

TEST(SuccessRatioCases, BoxTrialsFillTheBox) {
  const SearchBox box{2.0, 1.0, M_PI};
  double max_x = 0.0, max_y = 0.0, max_theta = 0.0;
  for (int trial = 0; trial < 500; ++trial) {
    const Pose2D error = boxTrialError(box, 11, trial, 3, nullptr);
    ASSERT_LE(std::abs(error.x), 2.0);
    ASSERT_LE(std::abs(error.y), 1.0);
    ASSERT_LE(std::abs(error.theta), M_PI);
    max_x = std::max(max_x, std::abs(error.x));
    max_y = std::max(max_y, std::abs(error.y));
    max_theta = std::max(max_theta, std::abs(error.theta));
  }
  EXPECT_GT(max_x, 1.9);
  EXPECT_GT(max_y, 0.95);
  EXPECT_GT(max_theta, 3.0);
}

TEST(SuccessRatio, ZeroErrorWithMbicpAlwaysSucceeds) {
  SuccessRatioOptions options = baseOptions();
  options.cases = {{0.0, 0.0}};
  const SuccessRatioReport report = run(roomScans(), options);
  ASSERT_EQ(report.rows.size(), 1u);
  const SuccessRatioRow& row = report.rows[0];
  EXPECT_EQ(row.trials, 20);
  EXPECT_EQ(row.successes, 20);
  EXPECT_DOUBLE_EQ(row.success_ratio, 1.0);
  EXPECT_LT(row.mean_dxy_m, 0.01);
  EXPECT_LT(row.mean_dth_deg, 0.1);
  EXPECT_GT(row.mean_ms, 0.0);
  EXPECT_EQ(report.scans_used, 4u);
  EXPECT_EQ(report.scans_skipped, 0u);
}

TEST(SuccessRatio, RecoversTheKnownErrorWhenTheMatcherCan) {
  // Small errors MbICP converges from, and the hybrid inside its small box: the truth is found.
  SuccessRatioOptions options = baseOptions();
  options.algorithms = {Algorithm::kMbicp, Algorithm::kHglasmG};
  options.cases = {{3.0, 0.05}, {10.0, 0.14}};
  const SuccessRatioReport report = run(roomScans(), options);
  ASSERT_EQ(report.rows.size(), 4u);
  for (const SuccessRatioRow& row : report.rows) {
    EXPECT_GE(row.success_ratio, 0.9) << successRatioCsvLine(row);
    EXPECT_LT(row.mean_dxy_m, 0.05) << successRatioCsvLine(row);
  }
  // The hybrid's mean error is far below the initial error it started from.
  EXPECT_LT(report.rows[3].mean_dxy_m, 0.14 / 4);
}

TEST(SuccessRatio, ErrorsOutsideTheBoxNeverCountAsSuccess) {
  // The small box is +-0.3 m / +-17 deg: a GA alone cannot get within 0.3 m of a 2.12 m error.
  SuccessRatioOptions options = baseOptions();
  options.algorithms = {Algorithm::kGlasmG, Algorithm::kGlasmBinary};
  options.cases = {{180.0, 2.12}};
  const SuccessRatioReport report = run(roomScans(), options);
  ASSERT_EQ(report.rows.size(), 2u);
  for (const SuccessRatioRow& row : report.rows) {
    EXPECT_EQ(row.successes, 0) << successRatioCsvLine(row);
    EXPECT_GT(row.mean_dxy_m, 2.12 - 0.3 * std::sqrt(2.0) - 1e-9);
    EXPECT_GT(row.mean_evaluations, 0.0);
  }
}

TEST(SuccessRatio, RowsComeInAlgorithmPresetCaseOrderWithBoxLast) {
  SuccessRatioOptions options = baseOptions();
  options.algorithms = {Algorithm::kMbicp, Algorithm::kGlasmG};
  options.presets = {Preset::kMedium, Preset::kSmall};
  options.cases = {{10.0, 0.14}, {0.0, 0.0}};
  options.in_box = true;
  options.trials = 3;
  const SuccessRatioReport report = run(roomScans(), options);
  ASSERT_EQ(report.rows.size(), 2u * 2u * 3u);
  std::vector<std::string> expected_prefixes;
  for (const char* algorithm : {"mbicp", "glasm_g"}) {
    for (const char* preset : {"medium", "small"}) {
      for (const char* ipe : {"10,0.14,", "0,0,", "box,box,"}) {
        expected_prefixes.push_back(std::string(algorithm) + "," + preset + "," + ipe + "3,");
      }
    }
  }
  for (std::size_t i = 0; i < report.rows.size(); ++i) {
    EXPECT_EQ(successRatioCsvLine(report.rows[i]).rfind(expected_prefixes[i], 0), 0u)
        << successRatioCsvLine(report.rows[i]) << " expected " << expected_prefixes[i];
  }
  EXPECT_EQ(successRatioCsvHeader(),
            "algorithm,preset,rot_err_deg,trans_err_m,trials,successes,success_ratio,mean_dxy_m,mean_dth_deg,"
            "mean_ms,ceiling");
}

TEST(SuccessRatio, SameSeedGivesTheSameRows) {
  SuccessRatioOptions options = baseOptions();
  options.algorithms = {Algorithm::kHglasmG, Algorithm::kGlasmBinary, Algorithm::kMbicp};
  options.cases = {{20.0, 0.57}, {10.0, 0.14}};
  options.in_box = true;
  options.trials = 10;
  const std::vector<RangeScan> scans = roomScans();
  const std::vector<std::string> first = linesWithoutTime(run(scans, options));
  const std::vector<std::string> second = linesWithoutTime(run(scans, options));
  EXPECT_EQ(first, second);

  // A case's trials do not depend on the other cases run with it.
  SuccessRatioOptions alone = options;
  alone.cases = {{10.0, 0.14}};
  alone.in_box = false;
  const std::vector<std::string> single = linesWithoutTime(run(scans, alone));
  ASSERT_EQ(single.size(), 3u);
  EXPECT_EQ(single[0], first[1]);  // hglasm_g: rows 20/0.57, 10/0.14, box
  EXPECT_EQ(single[1], first[4]);
  EXPECT_EQ(single[2], first[7]);
}

TEST(SuccessRatio, SkipsScansWithTooFewPointsAndReportsThem) {
  std::vector<RangeScan> scans = roomScans();
  RangeScan empty = scans[0];
  for (float& r : empty.ranges) r = std::nanf("");
  RangeScan sparse = scans[0];
  for (std::size_t i = 20; i < sparse.ranges.size(); ++i) sparse.ranges[i] = -1.0f;  // 20 valid beams
  scans.push_back(empty);
  scans.push_back(sparse);
  SuccessRatioOptions options = baseOptions();
  options.cases = {{0.0, 0.0}};
  const SuccessRatioReport report = run(scans, options);
  EXPECT_EQ(report.scans_total, 6u);
  EXPECT_EQ(report.scans_used, 4u);
  EXPECT_EQ(report.scans_skipped, 2u);
  EXPECT_EQ(report.rows.at(0).successes, 20);  // the skipped scans were never picked

  SuccessRatioReport none;
  std::string error;
  EXPECT_FALSE(runSuccessRatio({empty, sparse}, options, &none, &error));
  EXPECT_NE(error.find("valid points"), std::string::npos) << error;
}

TEST(SuccessRatio, RejectsOptionsThatRunNothing) {
  const std::vector<RangeScan> scans = roomScans();
  SuccessRatioReport report;
  std::string error;
  SuccessRatioOptions options = baseOptions();  // no cases, no box, no curves
  EXPECT_FALSE(runSuccessRatio(scans, options, &report, &error));
  options.cases = {{0.0, 0.0}};
  options.algorithms.clear();
  EXPECT_FALSE(runSuccessRatio(scans, options, &report, &error));
  options = baseOptions();
  options.cases = {{0.0, 0.0}};
  options.trials = 0;
  EXPECT_FALSE(runSuccessRatio(scans, options, &report, &error));
  options.trials = 1;
  options.cases = {{200.0, 0.0}};
  EXPECT_FALSE(runSuccessRatio(scans, options, &report, &error));
  EXPECT_FALSE(runSuccessRatio({}, baseOptions(), &report, &error));
}

TEST(SuccessRatio, EvaluationCurvesCompareBothTablesAtEqualEvaluations) {
  SuccessRatioOptions options = baseOptions();
  options.curve_trials = 8;
  options.curve_generations = {1, 4, 8};
  options.presets = {Preset::kSmall, Preset::kMedium};
  options.ceiling = false;
  std::vector<std::string> messages;
  SuccessRatioReport report;
  std::string error;
  ASSERT_TRUE(runSuccessRatio(roomScans(), options, &report, &error, [&](const SuccessRatioProgress& p) {
    messages.push_back(p.message);
    EXPECT_LE(p.cells_done, p.cells_total);
    EXPECT_EQ(p.cells_total, 18u);
  })) << error;
  EXPECT_TRUE(report.rows.empty());
  ASSERT_EQ(report.curve.size(), 2u * 3u * 3u);  // presets x (GLASM-g, binary GLASM, PGA) x generations
  EXPECT_EQ(messages.size(), 18u);
  EXPECT_EQ(report.curve[6].algorithm, Algorithm::kPga);
  for (std::size_t i = 0; i < report.curve.size(); i += 3) {
    const EvaluationCurvePoint* points = &report.curve[i];
    EXPECT_TRUE(points[0].algorithm == Algorithm::kGlasmG || points[0].algorithm == Algorithm::kGlasmBinary ||
                points[0].algorithm == Algorithm::kPga);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(points[k].generations, options.curve_generations[k]);
      EXPECT_EQ(points[k].trials, 8);
      EXPECT_GT(points[k].mean_evaluations, 0.0);
      if (k > 0) {
        EXPECT_GT(points[k].mean_evaluations, points[k - 1].mean_evaluations);
      }
      // The search alone is part of the whole; medians are errors too.
      EXPECT_GT(points[k].mean_search_ms, 0.0);
      EXPECT_LE(points[k].mean_search_ms, points[k].mean_ms + 1e-9);
      EXPECT_GE(points[k].median_dxy_m, 0.0);
      EXPECT_GE(points[k].median_dth_deg, 0.0);
    }
  }
  // The generation count is applied: every new (non-elite) individual of every generation is evaluated
  // (the GA may spend a few more, e.g. on the guess or a final polish). Equal-evaluation comparisons of the
  // two tables therefore read the curves at the same x (evaluations), not at the same generation count.
  for (const EvaluationCurvePoint& point : report.curve) {
    const GeneticOptions genetic = presetOptions(point.preset).genetic;
    EXPECT_EQ(point.population, genetic.population);
    EXPECT_EQ(point.runs, genetic.runs);
    const int evaluated_per_generation = genetic.population - std::max(genetic.elite_count, 0);
    EXPECT_GE(point.mean_evaluations,
              static_cast<double>(evaluated_per_generation * point.generations * genetic.runs));
  }
  EXPECT_EQ(evaluationCurveCsvLine(report.curve[0]).rfind("glasm_g,small,20,1,1,8,", 0), 0u)
      << evaluationCurveCsvLine(report.curve[0]);
}

TEST(SuccessRatio, WritesCsvAndPlotScripts) {
  SuccessRatioOptions options = baseOptions();
  options.cases = {{0.0, 0.14}, {20.0, 0.14}, {0.0, 0.57}, {20.0, 0.57}};
  options.in_box = true;
  options.trials = 2;
  options.curve_trials = 2;
  options.curve_generations = {1, 2};
  const SuccessRatioReport report = run(roomScans(), options);

  const std::string directory = ::testing::TempDir();
  std::string error;
  const std::string csv = directory + "/success_ratio_test.csv";
  ASSERT_TRUE(writeSuccessRatioCsv(csv, report.rows, &error)) << error;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, successRatioCsvHeader());
  int rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 10) << line;
  }
  EXPECT_EQ(rows, 5);
  EXPECT_TRUE(writeEvaluationCurveCsv(directory + "/success_ratio_test_curve.csv", report.curve, &error));
  EXPECT_FALSE(writeSuccessRatioCsv("/nonexistent/dir/x.csv", report.rows, &error));

  std::vector<std::string> scripts;
  ASSERT_TRUE(writeSuccessRatioPlotScripts(report, directory, "synthetic", &scripts, &error)) << error;
  // One success-vs-rotation plot (mbicp, small), one evaluations plot, one time-to-reach chart.
  ASSERT_EQ(scripts.size(), 3u);
  EXPECT_NE(scripts[0].find("success_mbicp_small.gp"), std::string::npos);
  EXPECT_NE(scripts[1].find("evaluations_small.gp"), std::string::npos);
  EXPECT_NE(scripts[2].find("time_to_reach.gp"), std::string::npos);
  std::ifstream gp(scripts[0]);
  std::stringstream text;
  text << gp.rdbuf();
  EXPECT_NE(text.str().find("success_mbicp_small.png"), std::string::npos);
  EXPECT_NE(text.str().find("index 1"), std::string::npos);  // two translation errors: two curves
}

TEST(SuccessRatio, CeilingIsTheSuccessAtZeroErrorBesideEveryRow) {
  SuccessRatioOptions options = baseOptions();
  options.algorithms = {Algorithm::kMbicp, Algorithm::kGlasmBinary};
  options.cases = {{20.0, 0.57}};
  options.in_box = true;
  options.trials = 10;
  const SuccessRatioReport report = run(roomScans(), options);
  ASSERT_EQ(report.rows.size(), 4u);
  // The ceiling is the case 0:0 run on its own.
  SuccessRatioOptions zero = options;
  zero.cases = {{0.0, 0.0}};
  zero.in_box = false;
  zero.ceiling = false;
  const SuccessRatioReport alone = run(roomScans(), zero);
  ASSERT_EQ(alone.rows.size(), 2u);
  for (const SuccessRatioRow& row : report.rows) {
    const SuccessRatioRow& reference = row.algorithm == Algorithm::kMbicp ? alone.rows[0] : alone.rows[1];
    EXPECT_EQ(row.ceiling_trials, 10);
    EXPECT_EQ(row.ceiling_successes, reference.successes);
    EXPECT_DOUBLE_EQ(row.ceiling, reference.success_ratio);
    EXPECT_EQ(alone.rows[0].ceiling, -1.0);  // not run: empty CSV field
  }
  EXPECT_EQ(report.rows[0].ceiling, 1.0);  // MbICP from the truth on simulated scans
  const std::string line = successRatioCsvLine(report.rows[0]);
  EXPECT_EQ(line.substr(line.rfind(',') + 1), "1.0000");
  const std::string empty = successRatioCsvLine(alone.rows[0]);
  EXPECT_EQ(empty.back(), ',');
  // The rows themselves do not depend on whether the ceiling ran.
  SuccessRatioOptions without = options;
  without.ceiling = false;
  std::vector<std::string> with_lines = linesWithoutTime(report),
                           without_lines = linesWithoutTime(run(roomScans(), without));
  for (std::string& l : with_lines) l = l.substr(0, l.rfind(','));  // drop the ceiling
  for (std::string& l : without_lines) l = l.substr(0, l.rfind(','));

  EXPECT_EQ(with_lines, without_lines);
}

TEST(SuccessRatio, HalfScanOffsetsMoveTheTruth) {
  // A half-scan offset of 0.02 rad (beyond the 0.01 rad threshold): matched from the identity, the
  // simulated halves (one instant) come out at the identity, which is now 0.02 rad from the truth.
  SuccessRatioOptions options = baseOptions();
  options.cases = {{0.0, 0.0}};
  options.ceiling = false;
  const std::vector<RangeScan> scans = roomScans();
  options.half_offsets.assign(scans.size(), Pose2D(0.0, 0.0, 0.02));
  const SuccessRatioReport moved = run(scans, options);
  EXPECT_EQ(moved.rows.at(0).successes, 0);
  EXPECT_NEAR(moved.rows[0].mean_dth_deg, 0.02 * 180.0 / M_PI, 0.05);
  options.half_offsets.assign(scans.size(), Pose2D());
  EXPECT_EQ(run(scans, options).rows.at(0).successes, 20);
  options.half_offsets.resize(1);
  SuccessRatioReport report;
  std::string error;
  EXPECT_FALSE(runSuccessRatio(scans, options, &report, &error));
}

TEST(SuccessRatio, HalfScanOffsetIsTheInverseOfTheLasersMotion) {
  // Turning at 1 rad/s, odd beams 14 ms after even ones: the even half is rotated by -0.014 rad.
  const Pose2D offset = halfScanOffset(Eigen::Vector3d(0.0, 0.0, 1.0), Pose2D(), 0.014);
  EXPECT_NEAR(offset.theta, -0.014, 1e-12);
  EXPECT_NEAR(offset.x, 0.0, 1e-12);
  // Driving forward at 0.5 m/s: the even half's sensor is 7 mm behind.
  const Pose2D forward = halfScanOffset(Eigen::Vector3d(0.5, 0.0, 0.0), Pose2D(), 0.014);
  EXPECT_NEAR(forward.x, -0.007, 1e-12);
  EXPECT_NEAR(forward.theta, 0.0, 1e-12);
  // A laser 0.04 m ahead of the base, turning on the spot: it also moves sideways (0.04 * 0.014 m).
  const Pose2D mounted = halfScanOffset(Eigen::Vector3d(0.0, 0.0, 1.0), Pose2D(0.04, 0.0, 0.0), 0.014);
  EXPECT_NEAR(mounted.theta, -0.014, 1e-12);
  EXPECT_NEAR(std::hypot(mounted.x, mounted.y), 0.04 * 2.0 * std::sin(0.007), 1e-9);
}

TEST(SuccessRatio, TimeToReachTakesTheFewestGenerationsThatReachTheLevel) {
  std::vector<EvaluationCurvePoint> curve;
  const double ratios[] = {0.40, 0.75, 0.72, 0.93};
  const int generations[] = {1, 2, 4, 8};
  for (int i = 0; i < 4; ++i) {
    EvaluationCurvePoint point;
    point.algorithm = Algorithm::kPga;
    point.preset = Preset::kLarge;
    point.generations = generations[i];
    point.success_ratio = ratios[i];
    point.mean_evaluations = 100.0 * generations[i];
    point.mean_search_ms = 1.0 * generations[i];
    point.mean_ms = 1.0 * generations[i] + 0.5;
    curve.push_back(point);
  }
  const std::vector<TimeToReach> entries = timeToReach(curve, {0.5, 0.7, 0.9, 0.95});
  ASSERT_EQ(entries.size(), 4u);
  EXPECT_TRUE(entries[0].reached);
  EXPECT_EQ(entries[0].generations, 2);  // 0.75 at 2 generations
  EXPECT_EQ(entries[1].generations, 2);
  EXPECT_DOUBLE_EQ(entries[1].search_ms, 2.0);
  EXPECT_DOUBLE_EQ(entries[1].total_ms, 2.5);
  EXPECT_EQ(entries[2].generations, 8);
  EXPECT_DOUBLE_EQ(entries[2].success_ratio, 0.93);
  EXPECT_FALSE(entries[3].reached);
  EXPECT_EQ(timeToReachCsvLine(entries[3]), "pga,large,0.95,0,,,,,");
  EXPECT_EQ(timeToReachCsvLine(entries[2]), "pga,large,0.90,1,8,800.0,0.9300,8.0000,8.5000");
  const std::string header = timeToReachCsvHeader();
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), 8);
}

}  // namespace
}  // namespace hglasm
