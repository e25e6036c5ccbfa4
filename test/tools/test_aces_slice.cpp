// bags/aces_slice.bag (aces: good wheel odometry, long corridors; 500 scans, 82 reference relations)
// through the nodelet's pipeline with the default configuration. The bounds hold with fusion (the scan
// matched with the wheels' prior) and fail when the match replaces the wheels: along the corridor at
// 1080 s the match then slides 0.8 m where the wheels are within centimetres.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "hglasm_odometry/core/odometry_pipeline.h"
#include "hglasm_odometry/evaluation/relations.h"
#include "hglasm_odometry/ros/parameters.h"
#include "hglasm_odometry/tools/bag_reader.h"

namespace hglasm_odometry {
namespace {

const std::string kBag = HGLASM_SOURCE_DIR "/bags/aces_slice.bag";
const std::string kRelations = HGLASM_SOURCE_DIR "/bags/aces_slice.relations";

// Measured with the defaults: mean 0.0277 m / 0.241 deg over the 82 relations (all within 10 s), largest
// 0.178 m; the slice's wheel odometry 0.0292 m / 0.752 deg. With fusion off: 0.0374 m, largest 0.126 m.
constexpr double kMaxMeanTranslation = 0.032;  // metres
constexpr double kMaxMeanRotationDeg = 0.30;
constexpr double kMaxTranslation = 0.20;  // metres: no relation may be off by more (no leap)

struct Accuracy {
  hglasm::RelationStats stats;
  double largest = 0.0;
  int fallbacks = 0;
};

Accuracy replay(bool fusion) {
  LaserOdometryOptions options;
  std::string error;
  EXPECT_TRUE(loadOptions(XmlRpc::XmlRpcValue(), &options, &error)) << error;  // the built-in defaults
  options.tracker.fusion = fusion;
  BagData data;
  EXPECT_TRUE(readBag(kBag, BagReadOptions(), &data, &error)) << error;
  hglasm::OdometryPipeline pipeline(options.tracker, options.odometry_wait > 0.0);
  pipeline.setLaserMount(data.base_to_laser, data.laser_upside_down);
  std::vector<hglasm::StampedPose> trajectory;
  Accuracy accuracy;
  auto next_odometry = data.odometry.begin();
  for (const BagScan& scan : data.scans) {
    next_odometry = pipeline.addRecordedOdometry(next_odometry, data.odometry.end(), scan.stamp);
    const hglasm::PipelineUpdate update = pipeline.processScan(scan.stamp, scan.ranges);
    accuracy.fallbacks += update.tracker.fallback;
    if (update.tracker.published) trajectory.push_back({scan.stamp, update.tracker.pose});
  }
  std::vector<hglasm::Relation> relations;
  EXPECT_TRUE(hglasm::readRelations(kRelations, &relations, &error)) << error;
  accuracy.stats = hglasm::evaluateRelations(relations, trajectory, 0.0);
  for (const auto& relation_error : hglasm::relationErrors(relations, trajectory, 0.0)) {
    accuracy.largest = std::max(accuracy.largest, relation_error.trans());
  }
  return accuracy;
}

TEST(AcesSlice, FusedOdometryHoldsAlongTheCorridor) {
  const Accuracy fused = replay(true);
  std::printf("[measured] fusion on: %d relations, %.4f m / %.3f deg, largest %.3f m, %d fallbacks\n",
              fused.stats.count, fused.stats.trans_mean, fused.stats.rot_mean_deg, fused.largest,
              fused.fallbacks);
  EXPECT_EQ(fused.stats.count, 82);
  EXPECT_EQ(fused.stats.missing, 0);
  EXPECT_EQ(fused.fallbacks, 0);
  EXPECT_LE(fused.stats.trans_mean, kMaxMeanTranslation);
  EXPECT_LE(fused.stats.rot_mean_deg, kMaxMeanRotationDeg);
  EXPECT_LE(fused.largest, kMaxTranslation);
}

TEST(AcesSlice, TheBoundsFailWhenTheMatchReplacesTheWheels) {
  const Accuracy replaced = replay(false);
  std::printf("[measured] fusion off: %.4f m / %.3f deg, largest %.3f m\n", replaced.stats.trans_mean,
              replaced.stats.rot_mean_deg, replaced.largest);
  EXPECT_TRUE(replaced.stats.trans_mean > kMaxMeanTranslation || replaced.largest > kMaxTranslation)
      << "the bounds above must catch an odometry that slides along the corridor";
}

}  // namespace
}  // namespace hglasm_odometry
