// HGLASM-g, the odometry's matcher: it recovers known poses, its MbICP stage refines the GA's pose (which
// MbICP alone cannot reach), the large preset recovers a 150-degree turn of a 360-degree scan, presets are
// Table 1, and bad input, matched or refined alone, gives a defined status with finite numbers.
#include "hglasm_odometry/core/scan_matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <set>

#include "bad_input_suite.h"
#include "test_util.h"

namespace {

using hglasm::MatchResult;
using hglasm::MatchStatus;
using hglasm::Pose2D;
using hglasm::Preset;
using hglasm::ScanMatcher;
using hglasm_test::BadInput;
using hglasm_test::deg;
using hglasm_test::describe;
using hglasm_test::expectFinite;

hglasm::MatcherOptions options(Preset preset, std::uint64_t seed = 1) {
  hglasm::MatcherOptions result = hglasm::presetOptions(preset);
  result.genetic.seed = seed;
  return result;
}

TEST(ScanMatcher, PresetNamesRoundTrip) {
  for (Preset preset : {Preset::kSmall, Preset::kMedium, Preset::kLarge}) {
    Preset parsed = preset == Preset::kSmall ? Preset::kLarge : Preset::kSmall;
    ASSERT_TRUE(hglasm::parsePreset(hglasm::toString(preset), &parsed));
    EXPECT_EQ(parsed, preset);
  }
  Preset preset = Preset::kMedium;
  EXPECT_FALSE(hglasm::parsePreset("huge", &preset));
  EXPECT_EQ(preset, Preset::kMedium);
  EXPECT_STREQ(hglasm::toString(Preset::kSmall), "small");
  EXPECT_STREQ(hglasm::toString(Preset::kMedium), "medium");
  EXPECT_STREQ(hglasm::toString(Preset::kLarge), "large");
}

TEST(ScanMatcher, PresetsAreTheirTable1Values) {
  const auto small = hglasm::presetOptions(Preset::kSmall).genetic;
  EXPECT_DOUBLE_EQ(small.box.half_x, 0.3);
  EXPECT_DOUBLE_EQ(small.box.half_y, 0.3);
  EXPECT_DOUBLE_EQ(small.box.half_theta, 0.3);
  EXPECT_EQ(small.population * small.generations * small.runs, 20 * 6 * 1);
  EXPECT_EQ(small.population, 20);
  EXPECT_EQ(small.generations, 6);
  const auto medium = hglasm::presetOptions(Preset::kMedium).genetic;
  EXPECT_DOUBLE_EQ(medium.box.half_x, 1.0);
  EXPECT_DOUBLE_EQ(medium.box.half_y, 1.0);
  EXPECT_DOUBLE_EQ(medium.box.half_theta, 1.0);
  EXPECT_EQ(medium.population, 100);
  EXPECT_EQ(medium.generations, 10);
  EXPECT_EQ(medium.runs, 1);
  const auto large = hglasm::presetOptions(Preset::kLarge).genetic;
  EXPECT_DOUBLE_EQ(large.box.half_x, 2.0);
  EXPECT_DOUBLE_EQ(large.box.half_y, 2.0);
  EXPECT_NEAR(large.box.half_theta, hglasm_test::kPi, 1e-12);
  EXPECT_EQ(large.population, 200);
  EXPECT_EQ(large.generations, 12);
  EXPECT_EQ(large.runs, 2);
}

/// Reference scan at the world origin; the new scan at `truth`, matched from the identity guess.
MatchResult matchInRoom(const hglasm::MatcherOptions& matcher_options, const hglasm_test::LaserSpec& laser,
                        const Pose2D& truth, const Pose2D& guess = Pose2D()) {
  const auto world = hglasm_test::room();
  ScanMatcher matcher(matcher_options);
  matcher.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  EXPECT_TRUE(matcher.hasReference());
  return matcher.match(hglasm_test::simulateScan(world, truth, laser), guess);
}

TEST(ScanMatcher, RecoversAKnownPose) {
  const Pose2D truth(0.18, -0.12, 0.15);  // inside the small box
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const MatchResult result =
        matchInRoom(options(Preset::kSmall, seed), hglasm_test::halfCircleLaser(), truth);
    expectFinite(result);
    EXPECT_EQ(result.status, MatchStatus::kOk) << describe(result);
    // The papers' success criterion for a final result.
    EXPECT_LT(hglasm_test::translationError(result.pose, truth), 0.01)
        << "seed " << seed << ": " << describe(result);
    EXPECT_LT(hglasm_test::rotationError(result.pose, truth), deg(0.2))
        << "seed " << seed << ": " << describe(result);
    EXPECT_GT(result.evaluations, 0);
    EXPECT_GT(result.prealigned_fitness, 0u);
    EXPECT_GT(result.iterations, 0);
    EXPECT_GT(result.associations, 0);
  }
}

TEST(ScanMatcher, RefineIsMbicpAloneFromTheGuess) {
  const Pose2D truth(0.05, -0.03, 0.04);
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  ScanMatcher matcher(options(Preset::kSmall));
  matcher.setReference(hglasm_test::simulateScan(world, Pose2D(), laser));
  const MatchResult result = matcher.refine(hglasm_test::simulateScan(world, truth, laser), Pose2D());
  expectFinite(result);
  EXPECT_EQ(result.status, MatchStatus::kOk) << describe(result);
  EXPECT_LT(hglasm_test::translationError(result.pose, truth), 0.01) << describe(result);
  EXPECT_EQ(result.evaluations, 0);
  EXPECT_EQ(result.prealigned_pose.x, 0.0);  // no GA: the guess is the pre-aligned pose
  EXPECT_EQ(result.prealigned_pose.theta, 0.0);
  EXPECT_GT(result.iterations, 0);
}

TEST(ScanMatcher, MbicpStageRefinesTheGeneticPose) {
  const Pose2D truth(0.62, 0.45, -0.7);  // inside the medium box, far outside MbICP's basin
  const MatchResult result = matchInRoom(options(Preset::kMedium), hglasm_test::halfCircleLaser(), truth);
  expectFinite(result);
  EXPECT_EQ(result.status, MatchStatus::kOk) << describe(result);
  // After a 0.77 m / 40 degree motion a fifth of the new scan sees what the reference did not: trimmed
  // MbICP then settles a millimetre or two and a tenth of a degree off even on noise-free scans (it does
  // so from the truth itself too), far inside the papers' 0.10 m / 0.01 rad.
  EXPECT_LT(hglasm_test::translationError(result.pose, truth), 5e-3) << describe(result);
  EXPECT_LT(hglasm_test::rotationError(result.pose, truth), deg(0.1)) << describe(result);
  EXPECT_LE(hglasm_test::translationError(result.pose, truth),
            hglasm_test::translationError(result.prealigned_pose, truth))
      << describe(result);
  // MbICP alone from the same guess does not get there.
  const auto world = hglasm_test::room();
  ScanMatcher matcher(options(Preset::kMedium));
  matcher.setReference(hglasm_test::simulateScan(world, Pose2D(), hglasm_test::halfCircleLaser()));
  const MatchResult alone =
      matcher.refine(hglasm_test::simulateScan(world, truth, hglasm_test::halfCircleLaser()), Pose2D());
  expectFinite(alone);
  EXPECT_FALSE(alone.ok() && hglasm_test::translationError(alone.pose, truth) < 0.1 &&
               hglasm_test::rotationError(alone.pose, truth) < 0.01)
      << "MbICP alone recovered a 0.77 m / 40 degree error: is the test scene too easy? " << describe(alone);
}

TEST(ScanMatcher, LargePresetRecoversA150DegreeTurnOfA360DegreeScan) {
  for (const Pose2D& truth :
       {Pose2D(0.5, -0.4, deg(150.0)), Pose2D(-0.7, 0.3, deg(-150.0)), Pose2D(1.2, 1.0, deg(175.0))}) {
    SCOPED_TRACE(testing::Message() << "truth " << truth.x << " " << truth.y << " " << truth.theta);
    const MatchResult result = matchInRoom(options(Preset::kLarge, 7), hglasm_test::fullCircleLaser(), truth);
    expectFinite(result);
    EXPECT_EQ(result.status, MatchStatus::kOk) << describe(result);
    EXPECT_LT(hglasm_test::translationError(result.pose, truth), 0.01) << describe(result);
    EXPECT_LT(hglasm_test::rotationError(result.pose, truth), deg(0.2)) << describe(result);
  }
}

TEST(ScanMatcher, GuessShiftsTheBox) {
  // A 0.8 m error is outside the small box around the identity, inside it around a good guess.
  const Pose2D truth(0.8, -0.3, 0.4);
  const MatchResult from_good_guess =
      matchInRoom(options(Preset::kSmall), hglasm_test::halfCircleLaser(), truth, Pose2D(0.65, -0.2, 0.3));
  EXPECT_EQ(from_good_guess.status, MatchStatus::kOk) << describe(from_good_guess);
  EXPECT_LT(hglasm_test::translationError(from_good_guess.pose, truth), 0.01) << describe(from_good_guess);
  EXPECT_LT(hglasm_test::rotationError(from_good_guess.pose, truth), deg(0.2)) << describe(from_good_guess);
}

TEST(ScanMatcher, SameSeedSameResult) {
  const auto world = hglasm_test::room();
  const auto laser = hglasm_test::halfCircleLaser();
  const auto reference = hglasm_test::simulateScan(world, Pose2D(), laser);
  const auto scan = hglasm_test::simulateScan(world, Pose2D(0.6, 0.2, -0.5), laser);
  ScanMatcher matcher(options(Preset::kMedium, 99));
  matcher.setReference(reference);
  const MatchResult first = matcher.match(scan, Pose2D());
  matcher.reseed(99);
  const MatchResult second = matcher.match(scan, Pose2D());
  EXPECT_EQ(first.pose.x, second.pose.x);
  EXPECT_EQ(first.pose.y, second.pose.y);
  EXPECT_EQ(first.pose.theta, second.pose.theta);
  EXPECT_EQ(first.prealigned_pose.x, second.prealigned_pose.x);
  EXPECT_EQ(first.prealigned_pose.theta, second.prealigned_pose.theta);
  EXPECT_EQ(first.prealigned_fitness, second.prealigned_fitness);
}

TEST(ScanMatcher, TheGradedTableIsBuiltOncePerReference) {
  const auto world = hglasm_test::room();
  const auto reference = hglasm_test::simulateScan(world, Pose2D(), hglasm_test::halfCircleLaser());
  ScanMatcher graded(options(Preset::kSmall));
  graded.setReference(reference);
  EXPECT_FALSE(graded.table().empty());
  EXPECT_EQ(graded.table().maxCellValue(), 255u);
  EXPECT_EQ(graded.table().valueAt(reference.points[10]), 255);
  EXPECT_GE(graded.lastTableBuildMs(), 0.0);
}

// ------------------------------------------------------------------ bad input

/// ScanMatcher under the bad-input contract: its match(), or its refine() (MbICP alone).
class OdometryMatcher : public hglasm_test::MatcherUnderTest {
 public:
  explicit OdometryMatcher(bool refine_only) : matcher_(options(Preset::kSmall)), refine_only_(refine_only) {}
  void setReference(const hglasm::Scan& reference) override { matcher_.setReference(reference); }
  bool hasReference() const override { return matcher_.hasReference(); }
  MatchResult match(const hglasm::Scan& scan, const Pose2D& guess) override {
    return refine_only_ ? matcher_.refine(scan, guess) : matcher_.match(scan, guess);
  }

 private:
  ScanMatcher matcher_;
  bool refine_only_;
};

hglasm_test::MatcherCase odometryCase(const std::string& name, bool refine_only) {
  return {name, true, [refine_only] { return std::make_unique<OdometryMatcher>(refine_only); }};
}

INSTANTIATE_TEST_SUITE_P(ScanMatcher, BadInput,
                         testing::Values(odometryCase("match", false), odometryCase("refine", true)),
                         hglasm_test::matcherCaseName);

TEST(ScanMatcher, StatusStringsAreDistinct) {
  std::set<std::string> names;
  for (MatchStatus status :
       {MatchStatus::kOk, MatchStatus::kNoReference, MatchStatus::kTooFewPoints, MatchStatus::kLowFitness,
        MatchStatus::kMbicpFailed, MatchStatus::kMbicpNotConverged}) {
    ASSERT_NE(hglasm::toString(status), nullptr);
    names.insert(hglasm::toString(status));
  }
  EXPECT_EQ(names.size(), 6u);
}

}  // namespace
