#include "hglasm_odometry/evaluation/statistics.h"

#include <algorithm>
#include <cmath>

namespace hglasm {
namespace {

/// Index of the nearest-rank percentile in a sorted sample of `size` > 0 values.
std::size_t rankIndex(std::size_t size, double fraction) {
  const std::size_t rank = static_cast<std::size_t>(std::ceil(fraction * size));
  return std::min(size - 1, rank == 0 ? 0 : rank - 1);
}

}  // namespace

double kthSmallest(std::vector<double> values, std::size_t k) {
  if (values.empty()) return 0.0;
  k = std::min(k, values.size() - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t half = values.size() / 2;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(half);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2) return *middle;
  return 0.5 * (*std::max_element(values.begin(), middle) + *middle);
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  const std::size_t index = rankIndex(values.size(), fraction);
  return kthSmallest(std::move(values), index);
}

double mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double value : values) sum += value;
  return values.empty() ? 0.0 : sum / values.size();
}

Spread spreadOf(std::vector<double> values) {
  Spread spread;
  spread.count = values.size();
  if (values.empty()) return spread;
  std::sort(values.begin(), values.end());
  spread.median = median(values);
  spread.p99 = values[rankIndex(values.size(), 0.99)];
  spread.max = values.back();
  spread.mean = mean(values);  // summed in ascending order
  return spread;
}

}  // namespace hglasm
