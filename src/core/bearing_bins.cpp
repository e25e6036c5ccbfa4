#include "hglasm_odometry/core/bearing_bins.h"

#include <algorithm>

namespace hglasm {
namespace {

constexpr int kMinBins = 64;
constexpr int kMaxBins = 8192;
constexpr double kSlack = 1e-9;  // relative: bounds stay bounds whatever the rounding

float roundedDown(double value) {
  const float rounded = static_cast<float>(value);
  return rounded > value ? std::nextafter(rounded, -std::numeric_limits<float>::infinity()) : rounded;
}

float roundedUp(double value) {
  const float rounded = static_cast<float>(value);
  return rounded < value ? std::nextafter(rounded, std::numeric_limits<float>::infinity()) : rounded;
}

/// atan2 within about 1e-5 rad: only a first guess of the bin, which the bins' edges then settle.
double roughBearing(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double a = std::min(ax, ay) / std::max(ax, ay);
  const double s = a * a;
  double angle = ((-0.0464964749 * s + 0.15931422) * s - 0.327622764) * s * a + a;
  if (ay > ax) angle = 0.5 * M_PI - angle;
  if (x < 0.0) angle = M_PI - angle;
  return y < 0.0 ? -angle : angle;
}

/// Distance from the origin to the segment a -> b.
double distanceToOrigin(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double length_sq = e.squaredNorm();
  const double t = length_sq > 0.0 ? std::clamp(-a.dot(e) / length_sq, 0.0, 1.0) : 0.0;
  return (a + t * e).norm();
}

}  // namespace

int BearingBins::binOf(const Eigen::Vector2d& p) const {
  const int bins = mask_ + 1;
  int bin = static_cast<int>((roughBearing(p.y(), p.x()) + M_PI) * bins_per_radian_);
  bin = std::clamp(bin, 0, mask_);
  // p lies counter-clockwise of (or on) the bin's clockwise edge and clockwise of the next one.
  const auto cross = [&](int edge) {
    return edges_[edge & mask_].x() * p.y() - edges_[edge & mask_].y() * p.x();
  };
  for (int k = 0; k < 4 && cross(bin) < 0.0; ++k) bin = (bin - 1) & mask_;
  for (int k = 0; k < 4 && cross(bin + 1) >= 0.0; ++k) bin = (bin + 1) & mask_;
  return bin < bins ? bin : 0;
}

void BearingBins::setMetric(double l_sq, double window) {
  l_sq_ = l_sq;
  cos_window_ = window >= M_PI ? -2.0 : std::cos(window);
  sin_sq_window_ = window >= 0.5 * M_PI ? 1.0 : std::sin(window) * std::sin(window);
}

void BearingBins::update(double range, double best, Bounds* bounds) const {
  const double root = std::sqrt(std::max(best, 0.0));
  const double far = range + root;
  bounds->range_high = far * (1.0 + kSlack) + kSlack;
  bounds->dot_limit = range * cos_window_ - kSlack * range;
  const double limit = l_sq_ > 0.0 ? std::max(best, 0.0) * (far * far + l_sq_) / l_sq_ : HUGE_VAL;
  bounds->bearing_bounded = limit < range * range;
  bounds->cross_sq_limit = limit * (1.0 + kSlack);
  bounds->window_binds = cos_window_ > -2.0 && (!bounds->bearing_bounded ||
                                                limit >= sin_sq_window_ * range * range * (1.0 - kSlack));
  bounds->range_low = bounds->bearing_bounded
                          ? range * std::sqrt(1.0 - limit / (range * range)) * (1.0 - kSlack) - root - kSlack
                          : -HUGE_VAL;
}

void BearingBins::setBinCount(int bins) {
  if (static_cast<int>(edges_.size()) != bins) {
    edges_.resize(bins);
    for (int k = 0; k < bins; ++k) {
      const double angle = -M_PI + 2.0 * M_PI * k / bins;
      edges_[k] = Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
  }
  mask_ = bins - 1;
  bins_per_radian_ = bins / (2.0 * M_PI);
}

void BearingBins::collectElements(const std::vector<Eigen::Vector2d>& points,
                                  const std::vector<std::int8_t>& has_next) {
  // A point or segment next to the origin has no bearing: it goes into every bin.
  constexpr double kNoBearing = 1e-6;
  const int n = static_cast<int>(points.size());
  const int bins = mask_ + 1;
  point_bin_.resize(points.size());
  directions_.resize(points.size());
  for (int i = 0; i < n; ++i) {
    const double range = points[i].norm();
    point_bin_[i] = range > kNoBearing ? binOf(points[i]) : -1;
    directions_[i] = range > kNoBearing ? Eigen::Vector2d(points[i] / range) : Eigen::Vector2d::Zero();
  }
  elements_.clear();
  for (int i = 0; i < n; ++i) {
    const double range = points[i].norm();
    const std::uint32_t code = static_cast<std::uint32_t>(i) << 1;
    const bool bearing = point_bin_[i] >= 0;
    elements_.push_back({bearing ? point_bin_[i] : 0, bearing ? 1 : bins, range, range, code});
    if (i + 1 >= n || !has_next[i]) continue;
    const Eigen::Vector2d& a = points[i];
    const Eigen::Vector2d& b = points[i + 1];
    Element segment{0, bins, distanceToOrigin(a, b), std::max(range, b.norm()), code | 1u};
    if (bearing && point_bin_[i + 1] >= 0 && segment.range_low > kNoBearing) {
      // The segment sweeps the shorter arc between its end points' bearings.
      const bool counter_clockwise = a.x() * b.y() - a.y() * b.x() >= 0.0;
      segment.first = counter_clockwise ? point_bin_[i] : point_bin_[i + 1];
      const int last = counter_clockwise ? point_bin_[i + 1] : point_bin_[i];
      segment.span = ((last - segment.first) & mask_) + 1;
    }
    elements_.push_back(segment);
  }
}

void BearingBins::build(const std::vector<Eigen::Vector2d>& points,
                        const std::vector<std::int8_t>& has_next) {
  const int n = static_cast<int>(points.size());
  int bins = kMinBins;
  while (bins * 2 < n && bins < kMaxBins) bins *= 2;
  setBinCount(bins);
  seen_.assign(points.size(), 0u);
  search_id_ = 0;
  collectElements(points, has_next);
  // Counting pass, then filling with starts_[bin + 1] as the cursor of `bin` (it ends at the bin's end).
  starts_.assign(bins + 1, 0u);
  std::size_t total = 0;
  for (const Element& element : elements_) {
    for (int k = 0; k < element.span; ++k) ++starts_[((element.first + k) & mask_) + 1];
    total += element.span;
  }
  for (int bin = 0; bin < bins; ++bin) starts_[bin + 1] += starts_[bin];
  for (int bin = bins; bin > 0; --bin) starts_[bin] = starts_[bin - 1];
  entries_.resize(total);
  for (const Element& element : elements_) {
    const Entry entry{roundedDown(element.range_low), roundedUp(element.range_high), element.code};
    for (int k = 0; k < element.span; ++k) entries_[starts_[((element.first + k) & mask_) + 1]++] = entry;
  }
  // By nearest range within each bin: a search stops at the first entry beyond its range band.
  for (int bin = 0; bin < bins; ++bin) {
    std::sort(entries_.begin() + starts_[bin], entries_.begin() + starts_[bin + 1],
              [](const Entry& a, const Entry& b) { return a.range_low < b.range_low; });
  }
}

}  // namespace hglasm
