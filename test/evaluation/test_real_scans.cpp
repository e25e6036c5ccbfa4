// Real scans (fixtures in test/data, extracted from the shared datasets; and the laserazos CARMEN log when
// ../shared/datasets is present): the papers' odd/even protocol with known offsets, and consecutive scans.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>

#include "../core/test_util.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/evaluation/carmen_log.h"

namespace {

using hglasm::MatchResult;
using hglasm::Pose2D;
using hglasm::Preset;
using hglasm::Scan;
using hglasm_test::deg;

// The papers' success criterion of a refined result.
constexpr double kSuccessXy = 0.10;
constexpr double kSuccessTheta = 0.01;

/// The scans of a fixture; with `spread_seconds` > 0 only scans at least that far apart in time (the
/// fixtures hold scans spread over the bag plus a block of consecutive ones).
std::vector<Scan> fixtureScans(const std::string& name, std::size_t expected_scans, int expected_beams,
                               double spread_seconds = 0.0) {
  const auto real = hglasm_test::loadScanFixture(hglasm_test::fixturePath(name));
  EXPECT_EQ(real.size(), expected_scans) << name << ": run test/data/extract_scans.py";
  std::vector<Scan> scans;
  double last_stamp = -1e300;
  for (const auto& scan : real) {
    EXPECT_EQ(static_cast<int>(scan.ranges.ranges.size()), expected_beams) << name;
    if (scan.stamp - last_stamp < spread_seconds) continue;
    last_stamp = scan.stamp;
    hglasm::ScanError error = hglasm::ScanError::kNone;
    scans.push_back(hglasm::scanFromRanges(scan.ranges, {}, &error));
    EXPECT_EQ(error, hglasm::ScanError::kNone) << name;
  }
  return scans;
}

/// Every `stride`-th FLASER scan of the laserazos log (the MbICP paper's data); empty if it is not there.
std::vector<Scan> laserazosScans(int stride) {
  hglasm::CarmenLog log;
  std::string error;
  if (!hglasm::readCarmenLog(hglasm_test::datasetPath("laserazos/laserazosSM3.log"), {}, &log, &error))
    return {};
  std::vector<Scan> scans;
  for (std::size_t i = 0; i < log.scans.size(); i += stride)
    scans.push_back(hglasm::scanFromRanges(log.scans[i].ranges));
  return scans;
}

/// Scans with at least 100 valid points.
std::vector<Scan> usable(const std::vector<Scan>& scans) {
  std::vector<Scan> out;
  for (const Scan& scan : scans) {
    if (scan.size() >= 100) out.push_back(scan);
  }
  return out;
}

struct Tally {
  int trials = 0;
  int successes = 0;
  std::string misses;
  double ratio() const { return trials ? static_cast<double>(successes) / trials : 0.0; }
};

/// What the odometry's matcher runs: HGLASM-g (match), or MbICP alone (refine).
enum class Stages { kHglasmG, kMbicpAlone };

/// The papers' protocol: reference = odd beams, new scan = even beams seen from `truth`. `offsets` gives
/// the initial position errors; the guess is the identity.
Tally oddEvenTrials(const std::vector<Scan>& scans, Preset preset, Stages stages,
                    const std::vector<Pose2D>& offsets) {
  Tally tally;
  hglasm::MatcherOptions options = hglasm::presetOptions(preset);
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const Scan reference = hglasm_test::beamsWithParity(scans[s], 1);
    const Scan even = hglasm_test::beamsWithParity(scans[s], 0);
    for (std::size_t k = 0; k < offsets.size(); ++k) {
      options.genetic.seed = 1000 * s + k + 1;
      hglasm::ScanMatcher matcher(options);
      matcher.setReference(reference);
      const Pose2D& truth = offsets[k];
      const Scan moved = hglasm_test::displacedScan(even, truth);
      const MatchResult result =
          stages == Stages::kHglasmG ? matcher.match(moved, Pose2D()) : matcher.refine(moved, Pose2D());
      EXPECT_TRUE(result.pose.isFinite());
      EXPECT_TRUE(result.covariance.allFinite());
      ++tally.trials;
      const double dxy = hglasm_test::translationError(result.pose, truth);
      const double dth = hglasm_test::rotationError(result.pose, truth);
      if (dxy < kSuccessXy && dth < kSuccessTheta) {
        ++tally.successes;
      } else {
        std::ostringstream text;
        text << "\n  scan " << s << " offset " << truth.x << " " << truth.y << " " << truth.theta
             << ": error " << dxy << " m " << dth << " rad, status " << hglasm::toString(result.status)
             << ", fitness " << result.prealigned_fitness_ratio;
        tally.misses += text.str();
      }
    }
  }
  return tally;
}

/// `count` offsets uniform in `fraction` of the preset's box (fixed seed).
std::vector<Pose2D> offsetsInBox(Preset preset, int count, double fraction, unsigned seed) {
  const auto box = hglasm::presetOptions(preset).genetic.box;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Pose2D> offsets;
  for (int i = 0; i < count; ++i) {
    offsets.emplace_back(fraction * box.half_x * unit(rng), fraction * box.half_y * unit(rng),
                         fraction * box.half_theta * unit(rng));
  }
  return offsets;
}

/// The papers' headline case: 20 degrees and 0.57 m in a few directions.
std::vector<Pose2D> headlineOffsets() {
  std::vector<Pose2D> offsets;
  for (double direction : {0.3, 2.1, 4.0}) {
    offsets.emplace_back(0.57 * std::cos(direction), 0.57 * std::sin(direction),
                         direction < 2.0 ? deg(20.0) : -deg(20.0));
  }
  return offsets;
}

void report(const std::string& what, const Tally& tally) {
  std::cout << "[ info     ] " << what << ": " << tally.successes << "/" << tally.trials << tally.misses
            << "\n";
}

std::vector<Scan> fr079Scans(double spread_seconds = 0.0) {
  return fixtureScans("fr079_scans.txt", 35, 360, spread_seconds);
}
std::vector<Scan> intelScans(double spread_seconds = 0.0) {
  return fixtureScans("intel_scans.txt", 36, 180, spread_seconds);
}
std::vector<Scan> ccnyScans() { return fixtureScans("ccny_scans.txt", 8, 681); }

/// Scans spread over both benchmark bags, plus the hand-held ccny scans: the odd/even pairs' sources.
std::vector<Scan> pairsSet() {
  std::vector<Scan> all;
  for (const auto& scans : {fr079Scans(5.0), intelScans(5.0), ccnyScans()}) {
    for (const Scan& scan : usable(scans)) all.push_back(scan);
  }
  return all;
}

TEST(RealScans, FixturesLoad) {
  ASSERT_EQ(fr079Scans().size(), 35u);
  ASSERT_EQ(intelScans().size(), 36u);
  ASSERT_EQ(ccnyScans().size(), 8u);
  for (const Scan& scan : fr079Scans()) EXPECT_GT(scan.size(), 100u);
  // The SICK "no return" readings (81.83 m > range_max 80) are invalid.
  for (const auto& real : hglasm_test::loadScanFixture(hglasm_test::fixturePath("fr079_scans.txt"))) {
    const Scan scan = hglasm::scanFromRanges(real.ranges);
    for (const auto& p : scan.points) EXPECT_LE(p.norm(), 80.0 + 1e-3);
  }
  EXPECT_GE(pairsSet().size(), 40u);  // 16 + 16 spread, 8 hand-held
}

TEST(RealScans, SmallPresetRecoversOddEvenPairsInItsBox) {
  const Tally tally =
      oddEvenTrials(pairsSet(), Preset::kSmall, Stages::kHglasmG, offsetsInBox(Preset::kSmall, 3, 0.9, 1));
  report("hglasm_g small, in 90 % of its box", tally);
  EXPECT_GE(tally.ratio(), 0.9) << tally.misses;
}

TEST(RealScans, MediumPresetRecoversTheHeadlineCase) {
  const Tally tally = oddEvenTrials(pairsSet(), Preset::kMedium, Stages::kHglasmG, headlineOffsets());
  report("hglasm_g medium, 20 deg + 0.57 m", tally);
  EXPECT_GE(tally.ratio(), 0.9) << tally.misses;
}

TEST(RealScans, LargePresetRecoversOddEvenPairsInItsWholeBox) {
  const Tally tally =
      oddEvenTrials(pairsSet(), Preset::kLarge, Stages::kHglasmG, offsetsInBox(Preset::kLarge, 3, 1.0, 2));
  report("hglasm_g large, in its whole box", tally);
  EXPECT_GE(tally.ratio(), 0.9) << tally.misses;
}

TEST(RealScans, MbicpRecoversSmallOffsets) {
  const std::vector<Pose2D> offsets = {Pose2D(0.05, -0.03, deg(2.0)), Pose2D(-0.08, 0.05, deg(-3.0)),
                                       Pose2D(0.0, 0.1, deg(1.0))};
  const Tally tally = oddEvenTrials(pairsSet(), Preset::kSmall, Stages::kMbicpAlone, offsets);
  report("mbicp, small offsets", tally);
  EXPECT_GE(tally.ratio(), 0.9) << tally.misses;
}

TEST(RealScans, LaserazosOddEvenPairs) {
  const std::vector<Scan> scans = usable(laserazosScans(50));
  if (scans.empty()) GTEST_SKIP() << "../shared/datasets/laserazos/laserazosSM3.log not found";
  EXPECT_GE(scans.size(), 14u);
  const Tally small =
      oddEvenTrials(scans, Preset::kSmall, Stages::kHglasmG, offsetsInBox(Preset::kSmall, 2, 0.9, 3));
  report("laserazos hglasm_g small", small);
  EXPECT_GE(small.ratio(), 0.9) << small.misses;
  const Tally medium = oddEvenTrials(scans, Preset::kMedium, Stages::kHglasmG, headlineOffsets());
  report("laserazos hglasm_g medium, 20 deg + 0.57 m", medium);
  EXPECT_GE(medium.ratio(), 0.9) << medium.misses;
}

struct Relation {
  double t1, t2;
  Pose2D motion;  ///< robot (base) at t2 in the robot frame at t1
};

/// The reference relations between scans of a fixture's consecutive block (test/data/*_relations.txt).
std::vector<Relation> loadRelations(const std::string& name) {
  std::vector<Relation> relations;
  std::ifstream in(hglasm_test::fixturePath(name));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t1, t2, x, y, z, roll, pitch, yaw;
    if (fields >> t1 >> t2 >> x >> y >> z >> roll >> pitch >> yaw) {
      relations.push_back({t1, t2, hglasm_test::rawPose(x, y, yaw)});
    }
  }
  return relations;
}

/// Consecutive scans of a fixture's block of 20, matched with the wheel odometry as the guess. Every match
/// must be finite and ok, and the chained laser motion must agree with the reference relations (manual
/// alignments, Kuemmerle et al.) between scans of the block.
void consecutiveScans(const std::string& scans_name, const std::string& relations_name,
                      const Pose2D& base_to_laser, int expected_relations) {
  const auto real = hglasm_test::loadScanFixture(hglasm_test::fixturePath(scans_name));
  ASSERT_GE(real.size(), 20u);
  hglasm::ScanMatcher matcher(hglasm::presetOptions(Preset::kSmall));
  // Base poses chained from the laser matches, per fixture scan index (only along the block).
  std::vector<Pose2D> chained(real.size());
  std::vector<bool> on_chain(real.size(), false);
  int pairs = 0, ok = 0;
  for (std::size_t i = 0; i + 1 < real.size(); ++i) {
    const auto& a = real[i];
    const auto& b = real[i + 1];
    if (b.stamp - a.stamp > 1.0 || !a.has_odometry || !b.has_odometry) continue;  // not consecutive
    const Pose2D base_motion = hglasm_test::relativeByHand(a.odometry, b.odometry);
    const Pose2D guess = base_to_laser.inverse() * base_motion * base_to_laser;
    matcher.setReference(hglasm::scanFromRanges(a.ranges));
    const MatchResult result = matcher.match(hglasm::scanFromRanges(b.ranges), guess);
    ++pairs;
    EXPECT_TRUE(result.pose.isFinite()) << scans_name << " pair " << i;
    EXPECT_TRUE(hglasm_test::isValidCovariance(result.covariance)) << scans_name << " pair " << i;
    EXPECT_TRUE(std::isfinite(result.prealigned_fitness_ratio) && std::isfinite(result.rms_error));
    EXPECT_TRUE(result.ok()) << scans_name << " pair " << i << ": " << hglasm::toString(result.status);
    if (result.ok()) ++ok;
    if (!on_chain[i]) on_chain[i] = true;  // the block's first scan is the origin of the chain
    chained[i + 1] = chained[i] * (base_to_laser * result.pose * base_to_laser.inverse());
    on_chain[i + 1] = true;
  }
  EXPECT_GE(pairs, 19);

  auto index_of = [&](double stamp) {
    for (std::size_t i = 0; i < real.size(); ++i) {
      if (std::abs(real[i].stamp - stamp) < 1e-4 && on_chain[i]) return static_cast<int>(i);
    }
    return -1;
  };
  const auto relations = loadRelations(relations_name);
  EXPECT_EQ(static_cast<int>(relations.size()), expected_relations) << relations_name;
  for (const Relation& relation : relations) {
    const int i1 = index_of(relation.t1), i2 = index_of(relation.t2);
    ASSERT_GE(i1, 0) << relation.t1;
    ASSERT_GE(i2, 0) << relation.t2;
    const Pose2D laser = hglasm_test::relativeByHand(chained[i1], chained[i2]);
    const Pose2D odometry = hglasm_test::relativeByHand(real[i1].odometry, real[i2].odometry);
    const double laser_xy = hglasm_test::translationError(laser, relation.motion);
    const double laser_theta = hglasm_test::rotationError(laser, relation.motion);
    std::cout << "[ info     ] " << scans_name << " relation " << std::fixed << std::setprecision(3)
              << relation.t1 << " -> " << relation.t2 << std::defaultfloat << " (" << i2 - i1
              << " scans): laser error " << laser_xy << " m " << laser_theta * 180.0 / M_PI
              << " deg; wheel odometry error " << hglasm_test::translationError(odometry, relation.motion)
              << " m " << hglasm_test::rotationError(odometry, relation.motion) * 180.0 / M_PI << " deg\n";
    EXPECT_LT(laser_xy, 0.05) << relation.t1;
    EXPECT_LT(laser_theta, deg(1.5)) << relation.t1;
  }
}

TEST(RealScans, ConsecutiveFr079ScansAgreeWithTheReferenceRelations) {
  consecutiveScans("fr079_scans.txt", "fr079_relations.txt", Pose2D(0.04, 0.0, 0.0), 2);  // laser 4 cm ahead
}

TEST(RealScans, ConsecutiveIntelScansAgreeWithTheReferenceRelations) {
  consecutiveScans("intel_scans.txt", "intel_relations.txt", Pose2D(), 3);
}

TEST(RealScans, ConsecutiveCcnyScansGiveFiniteResults) {
  // Hand-held, 4.5 s apart, no odometry: the match may fail, but it must say so with finite numbers.
  const std::vector<Scan> ccny = ccnyScans();
  hglasm::ScanMatcher matcher(hglasm::presetOptions(Preset::kLarge));
  for (std::size_t i = 0; i + 1 < ccny.size(); ++i) {
    matcher.setReference(ccny[i]);
    const MatchResult result = matcher.match(ccny[i + 1], Pose2D());
    EXPECT_TRUE(result.pose.isFinite());
    EXPECT_TRUE(hglasm_test::isValidCovariance(result.covariance));
    EXPECT_GE(result.prealigned_fitness_ratio, 0.0);
    EXPECT_LE(result.prealigned_fitness_ratio, 1.0);
  }
}

}  // namespace
