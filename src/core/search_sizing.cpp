#include "hglasm_odometry/core/search_sizing.h"

#include <algorithm>
#include <cmath>

#include "hglasm_odometry/core/scan_matcher.h"

namespace hglasm {

SearchEffort searchAround(const GeneticOptions& configured, const SearchOptions& options,
                          const Eigen::Matrix3d& covariance) {
  SearchEffort effort = effortOf(configured);
  const auto half_width = [&](int axis, double minimum, double maximum) {
    const double sigma = std::sqrt(std::max(0.0, covariance(axis, axis)));
    return std::clamp(options.sigmas * sigma, std::min(minimum, maximum), maximum);
  };
  effort.box.half_x = half_width(0, options.min_xy, configured.box.half_x);
  effort.box.half_y = half_width(1, options.min_xy, configured.box.half_y);
  effort.box.half_theta = half_width(2, options.min_theta, configured.box.half_theta);
  // The GA size of the smallest of the papers' presets whose box holds this one, capped by the configured
  // preset's (Table 1 grows box and GA together).
  for (Preset preset : {Preset::kSmall, Preset::kMedium}) {
    const GeneticOptions tier = presetOptions(preset).genetic;
    if (effort.box.half_x <= tier.box.half_x && effort.box.half_y <= tier.box.half_y &&
        effort.box.half_theta <= tier.box.half_theta) {
      effort.population = std::min(tier.population, configured.population);
      effort.generations = std::min(tier.generations, configured.generations);
      effort.runs = std::min(tier.runs, configured.runs);
      effort.coarse_generations = std::min(tier.coarse_generations, effort.generations);
      break;
    }
  }
  return effort;
}

Eigen::Vector3d boxVariances(const SearchBox& box, double sigmas) {
  return Eigen::Vector3d(box.half_x, box.half_y, box.half_theta).cwiseAbs2() / (sigmas * sigmas);
}

}  // namespace hglasm
