// How much of the configured preset's search a scan gets: the GA searches a few standard deviations of the
// prediction around it. The preset is the robot's worst case; the common case costs less.
#pragma once

#include <Eigen/Core>

#include "hglasm_odometry/core/genetic_aligner.h"

namespace hglasm {

struct SearchOptions {
  /// The GA searches this many standard deviations of the prediction on each axis, at least min_xy /
  /// min_theta and at most the preset's box, with the GA size of the smallest of the papers' presets whose
  /// box holds that (never more than the configured preset's); a box within a third of the small preset's
  /// on every axis with half its population and two thirds of its generations.
  double sigmas = 4.0;
  double min_xy = 0.10;     ///< metres
  double min_theta = 0.05;  ///< radians
};

/// The search around a prediction of `covariance` (x, y, theta) with the `configured` preset's GA.
SearchEffort searchAround(const GeneticOptions& configured, const SearchOptions& options,
                          const Eigen::Matrix3d& covariance);

/// The variances (x, y, theta) that put `box`'s half-widths at `sigmas` standard deviations.
Eigen::Vector3d boxVariances(const SearchBox& box, double sigmas);

}  // namespace hglasm
