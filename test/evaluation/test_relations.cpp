// The relations metric on synthetic trajectories with known answers, and the relations file reader.
#include "hglasm_odometry/evaluation/relations.h"

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace hglasm {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

/// A winding ground-truth path: one pose per second, stamps starting at `t0`.
std::vector<StampedPose> groundTruth(int count, double t0 = 1000.0) {
  std::vector<StampedPose> poses;
  Pose2D pose(1.0, -2.0, 0.3);
  for (int i = 0; i < count; ++i) {
    poses.push_back({t0 + i, pose});
    pose = pose * Pose2D(0.4 + 0.05 * (i % 3), 0.02 * ((i % 5) - 2), 0.1 * std::sin(0.7 * i));
  }
  return poses;
}

/// Relations between poses i and i + step (exact ground truth).
std::vector<Relation> relationsOf(const std::vector<StampedPose>& truth, int step) {
  std::vector<Relation> relations;
  for (std::size_t i = 0; i + step < truth.size(); ++i) {
    relations.push_back(
        {truth[i].stamp, truth[i + step].stamp, relativePose(truth[i].pose, truth[i + step].pose)});
  }
  return relations;
}

TEST(Relations, PerfectTrajectoryHasZeroError) {
  const auto truth = groundTruth(30);
  const auto relations = relationsOf(truth, 3);
  // Express the estimate in another odometry frame: the metric only sees relative motions.
  std::vector<StampedPose> estimate = truth;
  for (auto& pose : estimate) pose.pose = Pose2D(5.0, 7.0, 2.0) * pose.pose;

  const RelationStats stats = evaluateRelations(relations, estimate, 0.0);
  EXPECT_EQ(stats.count, 27);
  EXPECT_EQ(stats.missing, 0);
  EXPECT_NEAR(stats.trans_mean, 0.0, 1e-9);
  EXPECT_NEAR(stats.trans_std, 0.0, 1e-9);
  EXPECT_NEAR(stats.rot_mean_deg, 0.0, 1e-7);
  EXPECT_NEAR(stats.rot_std_deg, 0.0, 1e-7);
  EXPECT_NEAR(stats.trans_sq_mean, 0.0, 1e-12);
  EXPECT_NEAR(stats.rot_sq_mean_deg, 0.0, 1e-12);
}

TEST(Relations, ConstantBiasPerStepGivesThatBias) {
  // Each estimated step is the true step followed by the same small extra motion, so every one-step
  // relation's residual is exactly that extra motion.
  const Pose2D bias(0.03, -0.04, 0.02);
  const auto truth = groundTruth(40);
  std::vector<StampedPose> estimate = {truth[0]};
  for (std::size_t i = 1; i < truth.size(); ++i) {
    const Pose2D true_step = relativePose(truth[i - 1].pose, truth[i].pose);
    estimate.push_back({truth[i].stamp, estimate.back().pose * true_step * bias});
  }
  const RelationStats stats = evaluateRelations(relationsOf(truth, 1), estimate, 0.0);
  EXPECT_EQ(stats.count, 39);
  EXPECT_NEAR(stats.trans_mean, 0.05, 1e-9);
  EXPECT_NEAR(stats.trans_std, 0.0, 1e-9);
  EXPECT_NEAR(stats.trans_sq_mean, 0.0025, 1e-10);
  EXPECT_NEAR(stats.rot_mean_deg, 0.02 * kRadToDeg, 1e-7);
  EXPECT_NEAR(stats.rot_std_deg, 0.0, 1e-7);
  EXPECT_NEAR(stats.rot_sq_mean_deg, std::pow(0.02 * kRadToDeg, 2), 1e-7);
}

TEST(Relations, MeanStdAndSquaresOfDifferentErrors) {
  // Straight drive along x at 1 m/s estimated at 1.1 m/s: a relation over s seconds is off by 0.1 s.
  std::vector<StampedPose> estimate;
  for (int i = 0; i <= 10; ++i) estimate.push_back({static_cast<double>(i), Pose2D(1.1 * i, 0.0, 0.0)});
  const std::vector<Relation> relations = {{0.0, 1.0, Pose2D(1.0, 0.0, 0.0)},
                                           {2.0, 5.0, Pose2D(3.0, 0.0, 0.0)}};
  const RelationStats stats = evaluateRelations(relations, estimate, 0.0);
  EXPECT_EQ(stats.count, 2);
  EXPECT_NEAR(stats.trans_mean, 0.2, 1e-12);
  EXPECT_NEAR(stats.trans_std, 0.1, 1e-12);  // population standard deviation
  EXPECT_NEAR(stats.trans_sq_mean, (0.01 + 0.09) / 2.0, 1e-12);
  EXPECT_NEAR(stats.rot_mean_deg, 0.0, 1e-12);
}

TEST(Relations, AlongTrackScaleIsTheDistanceEstimatedAlongTheReferencesOverTheirs) {
  // 10 % too far along x, and a sideways error that does not count along the track; a relation that
  // hardly moves (5 cm) is left out of the scale.
  std::vector<StampedPose> estimate;
  for (int i = 0; i <= 10; ++i) estimate.push_back({static_cast<double>(i), Pose2D(1.1 * i, 0.05 * i, 0.0)});
  const std::vector<Relation> relations = {{0.0, 1.0, Pose2D(1.0, 0.0, 0.0)},
                                           {2.0, 5.0, Pose2D(3.0, 0.0, 0.0)},
                                           {6.0, 7.0, Pose2D(0.05, 0.0, 0.0)}};
  const RelationStats uniform = evaluateRelations(relations, estimate, 0.0);
  EXPECT_NEAR(uniform.along_track_scale, 1.1, 1e-12);
  EXPECT_EQ(uniform.along_track_count, 2);
  EXPECT_NEAR(uniform.along_track_scale_error, 0.0, 1e-12);  // every relation 10 % too far: no scatter
  // One that falls short by half: (1.1 + 3.3 + 0.5 * 2) / (1 + 3 + 2).
  estimate.push_back({20.0, Pose2D(0.0, 0.0, 0.0)});
  estimate.push_back({21.0, Pose2D(1.0, 0.0, 0.0)});
  std::vector<Relation> more = relations;
  more.push_back({20.0, 21.0, Pose2D(2.0, 0.0, 0.0)});
  const RelationStats mixed = evaluateRelations(more, estimate, 0.0);
  const double scale = (1.1 + 3.3 + 1.0) / 6.0;
  EXPECT_NEAR(mixed.along_track_scale, scale, 1e-12);
  // The scatter of each relation's distance along the track about the scale's share of it, n / (n - 1).
  const double scatter =
      std::pow(1.1 - scale * 1.0, 2) + std::pow(3.3 - scale * 3.0, 2) + std::pow(1.0 - scale * 2.0, 2);
  EXPECT_NEAR(mixed.along_track_scale_error, std::sqrt(scatter * 3.0 / 2.0) / 6.0, 1e-12);
  EXPECT_EQ(mixed.along_track_count, 3);
  EXPECT_EQ(evaluateRelations({{6.0, 7.0, Pose2D(0.05, 0.0, 0.0)}}, estimate, 0.0).along_track_scale, 0.0);
  // From 0.1 m on a relation counts; one alone gives a scale but no spread.
  const RelationStats single = evaluateRelations({{6.0, 7.0, Pose2D(0.1, 0.0, 0.0)}}, estimate, 0.0);
  EXPECT_NEAR(single.along_track_scale, 11.0, 1e-9);  // the estimate moves 1.1 m of the reference's 0.1 m
  EXPECT_EQ(single.along_track_count, 1);
  EXPECT_EQ(single.along_track_scale_error, 0.0);
}

TEST(Relations, RotationalErrorIsWrappedAndAbsolute) {
  // Reference turn of pi - 0.01, estimate -pi + 0.01 (the same heading crossed the other way):
  // a 0.02 rad error, not 2 pi - 0.02.
  const std::vector<StampedPose> estimate = {{0.0, Pose2D()}, {1.0, Pose2D(0.0, 0.0, -M_PI + 0.01)}};
  const std::vector<Relation> relations = {{0.0, 1.0, Pose2D(0.0, 0.0, M_PI - 0.01)}};
  const RelationStats stats = evaluateRelations(relations, estimate, 0.0);
  ASSERT_EQ(stats.count, 1);
  EXPECT_NEAR(stats.rot_mean_deg, 0.02 * kRadToDeg, 1e-9);

  // A negative residual counts by its magnitude.
  const std::vector<Relation> turn_left = {{0.0, 1.0, Pose2D(0.0, 0.0, 0.5)}};
  const std::vector<StampedPose> turned_less = {{0.0, Pose2D()}, {1.0, Pose2D(0.0, 0.0, 0.4)}};
  EXPECT_NEAR(evaluateRelations(turn_left, turned_less, 0.0).rot_mean_deg, 0.1 * kRadToDeg, 1e-9);
}

TEST(Relations, TranslationErrorIsMeasuredInTheRobotFrame) {
  // The estimate at t1 is rotated by 90 deg: the same relative motion is still exact, but the
  // t2 pose moved 0.2 m sideways in the world shows up as 0.2 m of error whatever the heading.
  const std::vector<StampedPose> estimate = {{0.0, Pose2D(3.0, 4.0, M_PI / 2)},
                                             {1.0, Pose2D(3.2, 5.0, M_PI / 2)}};
  const std::vector<Relation> relations = {{0.0, 1.0, Pose2D(1.0, 0.0, 0.0)}};
  const RelationStats stats = evaluateRelations(relations, estimate, 0.0);
  ASSERT_EQ(stats.count, 1);
  EXPECT_NEAR(stats.trans_mean, 0.2, 1e-12);
  EXPECT_NEAR(stats.rot_mean_deg, 0.0, 1e-12);
}

TEST(Relations, MissingStampsAreCountedNotEvaluated) {
  const auto truth = groundTruth(10);
  std::vector<Relation> relations = relationsOf(truth, 2);  // 8 relations
  relations[0].t1 += 0.01;                                  // beyond the default 1 ms tolerance: missing
  relations[1].t2 += 5e-6;                                  // within tolerance: still matched
  relations[2].t1 = 500.0;                                  // before the trajectory
  relations[3].t2 = 2000.0;                                 // after the trajectory
  const RelationStats stats = evaluateRelations(relations, truth, 0.0);
  EXPECT_EQ(stats.missing, 3);
  EXPECT_EQ(stats.count, 5);
  EXPECT_NEAR(stats.trans_mean, 0.0, 1e-9);

  // A looser tolerance finds the shifted stamp again.
  EXPECT_EQ(evaluateRelations(relations, truth, 0.0, 0.015).missing, 2);

  // An empty trajectory: everything missing, statistics stay zero.
  const RelationStats empty = evaluateRelations(relations, {}, 0.0);
  EXPECT_EQ(empty.count, 0);
  EXPECT_EQ(empty.missing, 8);
  EXPECT_EQ(empty.trans_mean, 0.0);
}

TEST(Relations, SpanFilterKeepsShortRelationsOnly) {
  std::vector<StampedPose> estimate;
  for (int i = 0; i <= 30; ++i) estimate.push_back({static_cast<double>(i), Pose2D(1.1 * i, 0.0, 0.0)});
  const std::vector<Relation> relations = {
      {0.0, 2.0, Pose2D(2.0, 0.0, 0.0)},     // span 2, error 0.2
      {10.0, 20.0, Pose2D(10.0, 0.0, 0.0)},  // span exactly 10: kept by <= 10, error 1.0
      {0.0, 30.0, Pose2D(30.0, 0.0, 0.0)},   // span 30, error 3.0
      {25.0, 5.0, Pose2D(-20.0, 0.0, 0.0)},  // backwards, span 20, error 2.0
  };
  const RelationStats short_ones = evaluateRelations(relations, estimate, 10.0);
  EXPECT_EQ(short_ones.count, 2);
  EXPECT_EQ(short_ones.missing, 0);
  EXPECT_NEAR(short_ones.trans_mean, 0.6, 1e-9);

  const RelationStats all = evaluateRelations(relations, estimate, 0.0);
  EXPECT_EQ(all.count, 4);
  EXPECT_NEAR(all.trans_mean, (0.2 + 1.0 + 3.0 + 2.0) / 4.0, 1e-9);

  // Filtered-out relations are not counted as missing even when their stamps are absent.
  const std::vector<Relation> long_absent = {{0.0, 100.0, Pose2D()}};
  EXPECT_EQ(evaluateRelations(long_absent, estimate, 10.0).missing, 0);
  EXPECT_EQ(evaluateRelations(long_absent, estimate, 0.0).missing, 1);
}

TEST(Relations, ReadsRelationsFile) {
  const std::string path = testing::TempDir() + "hglasm_test_relations.txt";
  {
    std::ofstream file(path);
    file << "# comment\n"
         << "1216.630413 1217.490267 0.407950 -0.016330 0.000000 0.000000 0.000000 -0.069620\n"
         << "\n"
         << "976052905.167303 976052911.885496 -0.05699 -0.12843 0.5 0.1 0.2 -1.68221\r\n";
  }
  std::vector<Relation> relations;
  std::string error;
  ASSERT_TRUE(readRelations(path, &relations, &error)) << error;
  ASSERT_EQ(relations.size(), 2u);
  EXPECT_DOUBLE_EQ(relations[0].t1, 1216.630413);
  EXPECT_DOUBLE_EQ(relations[0].t2, 1217.490267);
  EXPECT_DOUBLE_EQ(relations[0].motion.x, 0.407950);
  EXPECT_DOUBLE_EQ(relations[0].motion.y, -0.016330);
  EXPECT_DOUBLE_EQ(relations[0].motion.theta, -0.069620);
  EXPECT_NEAR(relations[1].t2 - relations[1].t1, 6.718193, 1e-6);  // stamps keep microseconds
  EXPECT_DOUBLE_EQ(relations[1].motion.theta, -1.68221);           // yaw, not roll or pitch

  {
    std::ofstream file(path);
    file << "1.0 2.0 0.1 0.2 0 0 0 0.3\n1.0 2.0 0.1\n";
  }
  EXPECT_FALSE(readRelations(path, &relations, &error));
  EXPECT_NE(error.find(":2:"), std::string::npos) << error;
  std::remove(path.c_str());

  EXPECT_FALSE(readRelations(path + ".does_not_exist", &relations, &error));
  EXPECT_FALSE(error.empty());
}

TEST(Relations, ReadsTheBenchmarkFiles) {
  const std::string root = HGLASM_SOURCE_DIR "/../shared/datasets/";
  std::vector<Relation> relations;
  std::string error;
  if (!readRelations(root + "fr079/fr079.relations", &relations, &error)) {
    GTEST_SKIP() << "dataset not available: " << error;
  }
  EXPECT_EQ(relations.size(), 1685u);
  for (const Relation& relation : relations) {
    ASSERT_TRUE(relation.motion.isFinite());
    ASSERT_NE(relation.t1, relation.t2);
  }
}

TEST(Relations, PairwiseMotionsUseTheSameMetric) {
  // Motions estimated pair by pair: the metric is the one of a trajectory holding the same motions.
  const std::vector<Relation> relations = {{0.0, 1.0, Pose2D(1.0, 0.0, 0.1)},
                                           {1.0, 2.0, Pose2D(0.5, 0.2, -0.2)},
                                           {2.0, 30.0, Pose2D(2.0, 0.0, 0.0)}};
  const std::vector<Pose2D> estimated = {Pose2D(1.05, 0.0, 0.1), Pose2D(0.5, 0.2, -0.15), Pose2D()};
  const std::vector<bool> valid = {true, true, false};
  const RelationStats stats = evaluateRelativeMotions(relations, estimated, valid, 10.0);
  EXPECT_EQ(stats.count, 2);
  EXPECT_EQ(stats.missing, 0);  // the invalid one spans 28 s: outside max_span, not missing
  EXPECT_NEAR(stats.trans_mean, 0.025, 1e-9);
  EXPECT_NEAR(stats.rot_mean_deg, 0.025 * kRadToDeg, 1e-9);
  const RelationStats all = evaluateRelativeMotions(relations, estimated, valid, 0.0);
  EXPECT_EQ(all.count, 2);
  EXPECT_EQ(all.missing, 1);
}

/// A trajectory whose every step is the true step (0.1 m forward, turning 0.02 rad) plus Gaussian noise of
/// the given covariance, and relations of the true motion over 4 steps.
struct NoisyRun {
  std::vector<StampedPose> trajectory;
  std::vector<Relation> relations;
};

NoisyRun noisyRun(const Eigen::Matrix3d& step_covariance, int steps, std::uint64_t seed) {
  NoisyRun run;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const Eigen::Matrix3d root = step_covariance.llt().matrixL();
  const Pose2D true_step(0.1, 0.0, 0.02);
  Pose2D estimate;
  run.trajectory.push_back({0.0, estimate});
  for (int i = 1; i <= steps; ++i) {
    const Eigen::Vector3d noise = root * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    estimate =
        estimate * Pose2D(true_step.x + noise.x(), true_step.y + noise.y(), true_step.theta + noise.z());
    run.trajectory.push_back({0.1 * i, estimate});
  }
  const Pose2D four_steps = true_step * true_step * true_step * true_step;
  for (int i = 0; i + 4 <= steps; i += 4) run.relations.push_back({0.1 * i, 0.1 * (i + 4), four_steps});
  return run;
}

TEST(Calibration, HonestCovariancesGiveAMeanSquaredMahalanobisDistanceOfThree) {
  const Eigen::Matrix3d step = Eigen::Vector3d(1e-4, 4e-5, 1e-5).asDiagonal();
  const NoisyRun run = noisyRun(step, 8000, 3);
  const std::vector<Eigen::Matrix3d> honest(run.trajectory.size(), step);
  const CalibrationStats stats = evaluateCalibration(run.relations, run.trajectory, honest, 10.0);
  EXPECT_EQ(stats.count, 2000);
  EXPECT_NEAR(stats.mean_sq_mahalanobis, 3.0, 0.2);
  EXPECT_NEAR(stats.median_sq_mahalanobis, 2.37, 0.2);  // the chi-square median for 3 degrees of freedom
  EXPECT_NEAR(stats.fraction_within_3dof_95, 0.95, 0.015);
  // Covariances 4 times too large read as a quarter; 4 times too small as four times.
  const std::vector<Eigen::Matrix3d> cautious(run.trajectory.size(), 4.0 * step);
  EXPECT_NEAR(evaluateCalibration(run.relations, run.trajectory, cautious, 10.0).mean_sq_mahalanobis, 0.75,
              0.06);
  const std::vector<Eigen::Matrix3d> confident(run.trajectory.size(), 0.25 * step);
  EXPECT_NEAR(evaluateCalibration(run.relations, run.trajectory, confident, 10.0).mean_sq_mahalanobis, 12.0,
              0.8);
}

TEST(Calibration, MismatchedInputsGiveNoStatistics) {
  const NoisyRun run = noisyRun(Eigen::Matrix3d::Identity() * 1e-4, 40, 4);
  const std::vector<Eigen::Matrix3d> too_few(3, Eigen::Matrix3d::Identity());
  EXPECT_EQ(evaluateCalibration(run.relations, run.trajectory, too_few, 10.0).count, 0);
}

TEST(Relations, PerRelationErrorsInTheOrderOfTheRelations) {
  const std::vector<StampedPose> trajectory = {
      {0.0, Pose2D()}, {1.0, Pose2D(1.0, 0.0, 0.0)}, {2.0, Pose2D(2.0, 0.1, 0.0)}};
  const std::vector<Relation> relations = {
      {0.0, 1.0, Pose2D(1.0, 0.0, 0.0)}, {1.0, 2.0, Pose2D(1.0, 0.0, 0.0)}, {0.0, 25.0, Pose2D()}};
  const std::vector<RelationError> errors = relationErrors(relations, trajectory, 10.0);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].index, 0u);
  EXPECT_NEAR(errors[0].trans(), 0.0, 1e-12);
  EXPECT_EQ(errors[1].index, 1u);
  EXPECT_NEAR(errors[1].trans(), 0.1, 1e-12);
}

/// A robot driving at 0.5 m/s whose turn rate swings as 0.5 sin(0.3 t) rad/s, its pose at time t (exact).
Pose2D swingingPoseAt(double t) {
  // theta(t) = (0.5 / 0.3) (1 - cos(0.3 t)); the position integrated finely (the fit reads headings only).
  Pose2D pose;
  const int steps = static_cast<int>(std::round(t / 0.01));
  for (int i = 0; i < steps; ++i) {
    const double heading = (0.5 / 0.3) * (1.0 - std::cos(0.3 * (i + 0.5) * 0.01));
    pose.x += 0.005 * std::cos(heading);
    pose.y += 0.005 * std::sin(heading);
  }
  pose.theta = (0.5 / 0.3) * (1.0 - std::cos(0.3 * t));
  return pose;
}

TEST(Timing, AnEstimateReadAFewMillisecondsLateFitsThatOffset) {
  std::vector<StampedPose> truth, late, early;
  for (int i = 0; i <= 600; ++i) {  // 60 s at 10 Hz
    const double t = 0.1 * i;
    truth.push_back({t, swingingPoseAt(t)});
    late.push_back({t, swingingPoseAt(t + 0.05)});
    early.push_back({t, swingingPoseAt(t - 0.03)});
  }
  std::vector<Relation> relations;
  for (std::size_t i = 10; i + 40 < truth.size(); i += 7) {  // turn rates known 0.3 s around
    relations.push_back(
        {truth[i].stamp, truth[i + 30].stamp, relativePose(truth[i].pose, truth[i + 30].pose)});
  }
  const auto fit = [&](const std::vector<StampedPose>& estimate) {
    std::vector<Pose2D> motions;
    std::vector<bool> valid;
    relativeMotions(relations, estimate, &motions, &valid);
    return fitTimingOffset(relations, motions, valid, truth, 10.0);
  };
  const TimingFit exact = fit(truth), read_late = fit(late), read_early = fit(early);
  EXPECT_EQ(exact.count, static_cast<int>(relations.size()));
  EXPECT_NEAR(exact.offset, 0.0, 1e-9);
  EXPECT_NEAR(read_late.offset, 0.05, 0.002);
  EXPECT_NEAR(read_early.offset, -0.03, 0.002);
  EXPECT_GT(read_late.rate_change, 0.1);  // the relations do see the turn rate change
}

TEST(Timing, AnEstimateThatOverCountsTurnsAndReadsLateFitsBoth) {
  // A laser whose bearings are 2 % wider than stated turns 2 % more in every match; read 40 ms late too.
  // Fitted alone, the offset would take part of the scale (relations that end in a turn see both).
  std::vector<StampedPose> truth, estimate;
  for (int i = 0; i <= 600; ++i) {
    const double t = 0.1 * i;
    truth.push_back({t, swingingPoseAt(t)});
    Pose2D pose = swingingPoseAt(t + 0.04);
    pose.theta *= 1.02;
    estimate.push_back({t, pose});
  }
  std::vector<Relation> relations;
  for (std::size_t i = 10; i + 40 < truth.size(); i += 7) {
    relations.push_back(
        {truth[i].stamp, truth[i + 30].stamp, relativePose(truth[i].pose, truth[i + 30].pose)});
  }
  std::vector<Pose2D> motions;
  std::vector<bool> valid;
  relativeMotions(relations, estimate, &motions, &valid);
  const TimingFit fit = fitTimingOffset(relations, motions, valid, truth, 10.0);
  EXPECT_EQ(fit.count, static_cast<int>(relations.size()));
  EXPECT_NEAR(fit.turn_scale, 0.02, 0.002);
  EXPECT_NEAR(fit.offset, 0.04, 0.003);  // 1.02 x 40 ms: the scaled heading is read late
  EXPECT_GT(fit.turn_scale_sd, 0.0);
  EXPECT_LT(fit.turn_scale_sd, 0.002);
}

TEST(Timing, LeapsAndRelationsWithoutTurnRatesAreLeftOut) {
  std::vector<StampedPose> truth;
  for (int i = 0; i <= 100; ++i) truth.push_back({0.1 * i, swingingPoseAt(0.1 * i)});
  const std::vector<Relation> relations = {
      {2.0, 4.0, relativePose(truth[20].pose, truth[40].pose)},  // fitted
      {4.0, 6.0, relativePose(truth[40].pose, truth[60].pose)},  // fitted
      {6.5, 8.5, relativePose(truth[65].pose, truth[85].pose)},  // fitted
      {5.0, 7.0, relativePose(truth[50].pose, truth[70].pose)},  // a 10 degree leap: left out
      {0.1, 2.0, relativePose(truth[1].pose, truth[20].pose)},   // no turn rate 0.3 s before t1
      {2.0, 9.0, relativePose(truth[20].pose, truth[90].pose)}   // longer than the span
  };
  std::vector<Pose2D> motions;
  std::vector<bool> valid;
  relativeMotions(relations, truth, &motions, &valid);
  ASSERT_EQ(valid, std::vector<bool>(6, true));
  motions[3].theta += 10.0 / kRadToDeg;
  const TimingFit fit = fitTimingOffset(relations, motions, valid, truth, 5.0);
  EXPECT_EQ(fit.count, 3);
  EXPECT_NEAR(fit.offset, 0.0, 1e-9);
  EXPECT_NEAR(fit.turn_scale, 0.0, 1e-9);
}

TEST(Relations, ARelationIsContradictedWhenItsScansAndTheWheelsAgreeAgainstIt) {
  const double deg = M_PI / 180.0;
  const std::vector<Relation> relations = {
      {0.0, 2.0, Pose2D(1.0, 0.0, 10.0 * deg)},  // scans and wheels both say 0 deg: contradicted
      {0.0, 2.0, Pose2D(1.0, 0.0, 10.0 * deg)},  // scans say 0, wheels 5: no witness agrees
      {0.0, 2.0, Pose2D(1.0, 0.0, 2.0 * deg)},   // scans 2 deg from the reference: within its error
      {0.0, 2.0, Pose2D(1.0, 0.0, 10.0 * deg)},  // no direct match
      {0.0, 20.0, Pose2D(1.0, 0.0, 10.0 * deg)}  // longer than the span
  };
  const std::vector<Pose2D> direct = {Pose2D(1.0, 0.0, 0.0), Pose2D(1.0, 0.0, 0.0), Pose2D(1.0, 0.0, 0.0),
                                      Pose2D(), Pose2D(1.0, 0.0, 0.0)};
  const std::vector<bool> direct_valid = {true, true, true, false, true};
  const std::vector<Pose2D> wheels = {Pose2D(1.0, 0.0, 0.5 * deg), Pose2D(1.0, 0.0, 5.0 * deg),
                                      Pose2D(1.0, 0.0, 0.0), Pose2D(1.0, 0.0, 0.0), Pose2D(1.0, 0.0, 0.0)};
  const std::vector<bool> wheels_valid(5, true);
  const std::vector<bool> contradicted = contradictedRelations(relations, direct, direct_valid, wheels,
                                                               wheels_valid, 10.0, 3.0 * deg, 1.0 * deg);
  EXPECT_EQ(contradicted, std::vector<bool>({true, false, false, false, false}));
}

}  // namespace
}  // namespace hglasm
