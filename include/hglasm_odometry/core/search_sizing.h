// How much of the configured preset's search a scan gets: the GA searches a few standard deviations of the
// prediction around it. The preset is the robot's worst case; the common case costs less.
#pragma once

#include <Eigen/Core>
#include <cmath>

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

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, SearchOptions* options) {
  visitor.positiveNumber("search/sigmas", &options->sigmas);
  visitor.nonNegativeNumber("search/min_xy", &options->min_xy);
  visitor.number("search/min_theta", &options->min_theta, 0.0, M_PI);
}

/// The search around a prediction of `covariance` (x, y, theta) with the `configured` preset's GA.
SearchEffort searchAround(const GeneticOptions& configured, const SearchOptions& options,
                          const Eigen::Matrix3d& covariance);

/// The variances (x, y, theta) that put `box`'s half-widths at `sigmas` standard deviations.
Eigen::Vector3d boxVariances(const SearchBox& box, double sigmas);

}  // namespace hglasm
