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
  // A box a third of the small preset's on every axis (a 27th of its volume, the usual case with wheels)
  // needs fewer candidates to find its basin: half the population and two thirds of the generations.
  const SearchBox small = presetOptions(Preset::kSmall).genetic.box;
  const auto within_third = [](double half_width, double small_half_width) {
    return half_width <= small_half_width / 3.0 * (1.0 + 1e-9);
  };
  if (within_third(effort.box.half_x, small.half_x) && within_third(effort.box.half_y, small.half_y) &&
      within_third(effort.box.half_theta, small.half_theta)) {
    effort.population =
        std::max(1, std::min(effort.population, (presetOptions(Preset::kSmall).genetic.population + 1) / 2));
    effort.generations =
        std::max(1, std::min(effort.generations, 2 * presetOptions(Preset::kSmall).genetic.generations / 3));
  }
  return effort;
}

Eigen::Vector3d boxVariances(const SearchBox& box, double sigmas) {
  return Eigen::Vector3d(box.half_x, box.half_y, box.half_theta).cwiseAbs2() / (sigmas * sigmas);
}

}  // namespace hglasm
