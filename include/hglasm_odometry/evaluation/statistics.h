// Order statistics of samples (CPU times, errors), the one implementation the tools and the evaluation use.
#pragma once

#include <cstddef>
#include <vector>

namespace hglasm {

/// The k-th smallest value (0-based, k clamped to the last); 0 for no values.
double kthSmallest(std::vector<double> values, std::size_t k);

/// The median (the mean of the two middle values for an even count); 0 for no values.
double median(std::vector<double> values);

/// The nearest-rank percentile: the smallest value with at least `fraction` of the values at or below it
/// (fraction 1: the maximum); 0 for no values.
double percentile(std::vector<double> values, double fraction);

/// The arithmetic mean, summed in the given order; 0 for no values.
double mean(const std::vector<double>& values);

/// A sample's size, median, nearest-rank 99th percentile, maximum and mean.
struct Spread {
  std::size_t count = 0;
  double median = 0.0, p99 = 0.0, max = 0.0, mean = 0.0;
};

Spread spreadOf(std::vector<double> values);

}  // namespace hglasm
