// The search around a prediction: a few standard deviations on each axis, within the floor and the
// preset's box, with the GA size of the smallest of the papers' presets that holds it.
#include "hglasm_odometry/core/search_sizing.h"

#include <gtest/gtest.h>

#include "hglasm_odometry/core/scan_matcher.h"

namespace {

using hglasm::GeneticOptions;
using hglasm::SearchEffort;
using hglasm::SearchOptions;

TEST(SearchSizing, ATightPredictionGetsTheFloorAndASmallerGaThanTheSmallPresets) {
  const GeneticOptions medium = hglasm::presetOptions(hglasm::Preset::kMedium).genetic;
  const SearchEffort effort =
      hglasm::searchAround(medium, SearchOptions(), Eigen::Vector3d(1e-6, 1e-6, 1e-8).asDiagonal());
  EXPECT_EQ(effort.box.half_x, 0.10);
  EXPECT_EQ(effort.box.half_y, 0.10);
  EXPECT_EQ(effort.box.half_theta, 0.05);
  // The floor box is a third of the small preset's on every axis: half its population, 2/3 of its
  // generations.
  EXPECT_EQ(effort.population, 10);
  EXPECT_EQ(effort.generations, 4);
  EXPECT_EQ(effort.coarse_generations, 0);
}

TEST(SearchSizing, ABoxBeyondAThirdOfTheSmallPresetsOnOneAxisGetsTheSmallPresetsGa) {
  const GeneticOptions medium = hglasm::presetOptions(hglasm::Preset::kMedium).genetic;
  // x: 4 sigma = 0.12 m, beyond a third of 0.3 m; y and theta at the floor.
  const SearchEffort effort =
      hglasm::searchAround(medium, SearchOptions(), Eigen::Vector3d(0.0009, 1e-6, 1e-8).asDiagonal());
  EXPECT_NEAR(effort.box.half_x, 0.12, 1e-12);
  EXPECT_EQ(effort.population, 20);
  EXPECT_EQ(effort.generations, 6);
}

TEST(SearchSizing, TheBoxIsSigmasStandardDeviationsCappedByThePresets) {
  const GeneticOptions medium = hglasm::presetOptions(hglasm::Preset::kMedium).genetic;
  // 4 sigma of 0.1 m is 0.4 m: beyond the small preset's 0.3 m, so the medium GA; theta 4 * 1 rad capped.
  const SearchEffort effort =
      hglasm::searchAround(medium, SearchOptions(), Eigen::Vector3d(0.01, 0.0025, 1.0).asDiagonal());
  EXPECT_NEAR(effort.box.half_x, 0.4, 1e-12);
  EXPECT_NEAR(effort.box.half_y, 0.2, 1e-12);
  EXPECT_EQ(effort.box.half_theta, medium.box.half_theta);
  EXPECT_EQ(effort.population, medium.population);
  EXPECT_EQ(effort.generations, medium.generations);
}

TEST(SearchSizing, NeverMoreThanTheConfiguredPresetsGa) {
  GeneticOptions tiny = hglasm::presetOptions(hglasm::Preset::kMedium).genetic;
  tiny.population = 8;
  tiny.generations = 3;
  const SearchEffort effort = hglasm::searchAround(tiny, SearchOptions(), Eigen::Matrix3d::Zero());
  EXPECT_EQ(effort.population, 8);
  EXPECT_EQ(effort.generations, 3);
  EXPECT_EQ(effort.coarse_generations, 0);
}

TEST(SearchSizing, BoxVariancesPutTheHalfWidthsAtSigmas) {
  const Eigen::Vector3d variances = hglasm::boxVariances(hglasm::SearchBox{0.8, 0.4, 0.2}, 4.0);
  EXPECT_NEAR(variances.x(), 0.04, 1e-15);
  EXPECT_NEAR(variances.y(), 0.01, 1e-15);
  EXPECT_NEAR(variances.z(), 0.0025, 1e-15);
}

}  // namespace
