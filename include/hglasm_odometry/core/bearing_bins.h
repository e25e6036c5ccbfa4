// Reference points and segments binned by bearing around their frame's origin, for MbICP's association:
// a search visits only the bins and the ranges where the d_ap metric can still beat the best candidate.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace hglasm {

/// Bins of equal bearing width around the origin. Each bin lists the points whose bearing lies in it and
/// the segments (from point i to point i + 1) that pass through it, with their range interval, nearest
/// first.
///
/// The search is exact for the d_ap metric (MbICP's, with the rotation linearised at the candidate q):
///   d_ap^2 = (|p| cos D - |q|)^2 + |p|^2 sin^2 D L^2 / (|q|^2 + L^2),  D the bearing between p and q.
/// A candidate below `best` therefore has |q| < |p| + sqrt(best) and sin^2 D < s^2 = best ((|p| +
/// sqrt(best))^2 + L^2) / (|p|^2 L^2), so D < asin(s) when s < 1 (for D beyond pi/2 the first term alone
/// exceeds best), and |q| > |p| cos D - sqrt(best). Bins are skipped by their edges' cross products with p
/// (no trigonometry per query), entries by their range interval.
class BearingBins {
 public:
  /// Rebuilds for `points` (all finite) with a segment from i to i + 1 wherever has_next[i].
  void build(const std::vector<Eigen::Vector2d>& points, const std::vector<std::int8_t>& has_next);

  /// The metric's L^2, and how far in bearing from p candidates may lie (radians, at most pi).
  void setMetric(double l_sq, double window);

  /// Calls visit(index, is_segment) for every point and segment that may lie closer to p than *best
  /// (d_ap^2) within the window: a point whose bearing is within it of p's, a segment with such an end
  /// point. visit may lower *best: the search narrows as it does.
  /// Segments are visited at most once per search; `skip` (index * 2 + is_segment, or -1) not at all.
  template <typename Visit>
  void search(const Eigen::Vector2d& p, double* best, std::int64_t skip, Visit&& visit);

  std::size_t binCount() const { return edges_.size(); }
  /// The bin holding bearing atan2(p.y, p.x) (exactly, by the bins' edges). p must be finite and not zero.
  int binOf(const Eigen::Vector2d& p) const;

 private:
  struct Entry {
    float range_low;     // rounded down
    float range_high;    // rounded up
    std::uint32_t code;  // index * 2 + is_segment
  };
  /// What the current best allows: bins within the bearing bound, entries within the range band.
  struct Bounds {
    bool bearing_bounded = false;  // s < 1: cross^2 < cross_sq_limit bounds the bearing
    double cross_sq_limit = 0.0;   // s^2 |p|^2
    double dot_limit = 0.0;        // dot with an edge must exceed this (the window)
    bool window_binds = false;     // the window, not the metric, limits the bearing: elements checked
    double range_low = 0.0;
    double range_high = 0.0;
  };
  void update(double range, double best, Bounds* bounds) const;
  /// True if a bin whose nearest edge has this dot and cross product with p may hold a candidate.
  bool withinWindow(const Eigen::Vector2d& p, std::uint32_t index, bool segment, const Bounds& bounds) const {
    const auto within = [&](std::uint32_t i) {
      return directions_[i].isZero() || p.dot(directions_[i]) > bounds.dot_limit;
    };
    return within(index) || (segment && within(index + 1));
  }
  static bool mayHold(double dot, double cross, const Bounds& bounds) {
    return dot > bounds.dot_limit &&
           (!bounds.bearing_bounded || (dot > 0.0 && cross * cross < bounds.cross_sq_limit));
  }
  /// A point or segment: the bins it lies in (first, then counter-clockwise) and its range interval.
  struct Element {
    int first;
    int span;
    double range_low;
    double range_high;
    std::uint32_t code;
  };
  void setBinCount(int bins);
  void collectElements(const std::vector<Eigen::Vector2d>& points, const std::vector<std::int8_t>& has_next);

  double l_sq_ = 9.0;
  double cos_window_ = -2.0;  // -2: no window
  double sin_sq_window_ = 0.0;
  std::vector<Eigen::Vector2d> directions_;  // unit bearing of each point (zero next to the origin)
  int mask_ = 0;
  double bins_per_radian_ = 0.0;
  std::vector<Eigen::Vector2d> edges_;  // unit vector of each bin's clockwise edge
  std::vector<std::uint32_t> starts_;   // per bin, into entries_ (bins + 1)
  std::vector<Entry> entries_;
  std::vector<std::uint32_t> seen_;  // per segment: the search that last visited it
  std::uint32_t search_id_ = 0;
  // Scratch of build().
  std::vector<int> point_bin_;
  std::vector<Element> elements_;
};

template <typename Visit>
void BearingBins::search(const Eigen::Vector2d& p, double* best, std::int64_t skip, Visit&& visit) {
  if (edges_.empty() || !p.allFinite()) return;
  if (++search_id_ == 0) {
    std::fill(seen_.begin(), seen_.end(), 0u);
    search_id_ = 1;
  }
  const double range = p.norm();
  const int bins = mask_ + 1;
  Bounds bounds;
  double bounds_best = *best;
  update(range, bounds_best, &bounds);
  const auto visit_bin = [&](int bin) {
    for (std::uint32_t k = starts_[bin], end = starts_[bin + 1]; k < end; ++k) {
      const Entry& entry = entries_[k];
      if (entry.range_low > bounds.range_high) break;
      if (entry.range_high < bounds.range_low) continue;
      if (entry.code == skip) continue;
      const std::uint32_t index = entry.code >> 1;
      const bool segment = entry.code & 1u;
      if (bounds.window_binds && !withinWindow(p, index, segment, bounds)) continue;
      if (segment) {
        if (seen_[index] == search_id_) continue;
        seen_[index] = search_id_;
      }
      visit(static_cast<int>(index), segment);
      // Bounds from a larger best still hold (looser): refreshed on a real gain only.
      if (*best < 0.5 * bounds_best) {
        bounds_best = *best;
        update(range, bounds_best, &bounds);
      }
    }
  };
  if (!(range > 1e-9)) {
    for (int bin = 0; bin < bins; ++bin) visit_bin(bin);  // no bearing: every bin
    return;
  }
  const int own = binOf(p);
  visit_bin(own);
  // Outward both ways; each bin once.
  bool ccw_open = true, cw_open = true;
  int visited = 1;
  for (int step = 1; (ccw_open || cw_open) && visited < bins; ++step) {
    if (ccw_open) {
      const Eigen::Vector2d& edge = edges_[(own + step) & mask_];  // the bin's clockwise edge
      ccw_open = mayHold(p.dot(edge), p.x() * edge.y() - p.y() * edge.x(), bounds);
      if (ccw_open) visit_bin((own + step) & mask_), ++visited;
    }
    if (cw_open && visited < bins) {
      const Eigen::Vector2d& edge = edges_[(own - step + 1) & mask_];  // the bin's counter-clockwise edge
      cw_open = mayHold(p.dot(edge), edge.x() * p.y() - edge.y() * p.x(), bounds);
      if (cw_open) visit_bin((own - step) & mask_), ++visited;
    }
  }
}

}  // namespace hglasm
