#include "hglasm_odometry/core/local_map.h"

#include <algorithm>
#include <cmath>

namespace hglasm {

LocalMap::LocalMap(const LocalMapOptions& options) : options_(options) {
  options_.keyframes = std::max(1, options_.keyframes);
}

void LocalMap::add(const Pose2D& laser_pose, const std::vector<Eigen::Vector2d>& points) {
  keyframes_.push_back(Keyframe{laser_pose, points});
  while (keyframes_.size() > static_cast<std::size_t>(options_.keyframes)) keyframes_.pop_front();
  while (keyframes_.size() > 1 &&
         (keyframes_.front().laser_pose.translation() - laser_pose.translation()).norm() >
             options_.max_distance) {
    keyframes_.pop_front();
  }
  rebuild();
}

void LocalMap::clear() {
  keyframes_.clear();
  reference_.clear();
  frame_ = Pose2D();
  ++revision_;
}

void LocalMap::rebuild() {
  ++revision_;
  reference_.clear();
  if (keyframes_.empty()) return;
  std::size_t total = 0;
  for (const Keyframe& keyframe : keyframes_) total += keyframe.points.size();
  resetGrid(total);
  frame_ = keyframes_.back().laser_pose;
  const Pose2D to_frame = frame_.inverse();
  // Oldest first: where keyframes overlap, the oldest view stays, so the map holds its shape while the
  // robot moves through it instead of following the newest keyframe's error.
  for (const Keyframe& keyframe : keyframes_) {
    const Pose2D pose = to_frame * keyframe.laser_pose;
    // A keyframe is never thinned by its own points (its beams keep their spacing), only by other keyframes'.
    const std::size_t first = reference_.size();
    const std::vector<Eigen::Vector2d>& points = keyframe.points;
    transformPoints(points, pose, &moved_);
    covered_.assign(points.size(), 0);
    if (options_.resolution > 0.0 && !remembered_.empty()) {
      for (std::size_t i = 0; i < points.size(); ++i) covered_[i] = covered(moved_[i]);
    }
    // A kept point keeps its neighbouring beams too, covered or not: the surface it lies on stays a surface
    // (alone, a thinned wall's survivors would be isolated points, precise along their beams, which along
    // a corridor's wall is the direction nothing observes).
    kept_.clear();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const bool neighbour_kept = (i > 0 && !covered_[i - 1]) || (i + 1 < points.size() && !covered_[i + 1]);
      if (!covered_[i] || neighbour_kept) kept_.push_back(moved_[i]);
    }
    reference_.appendMoved(kept_, pose.translation());
    if (options_.resolution > 0.0) {
      for (std::size_t i = first; i < reference_.size(); ++i) remember(reference_.points[i]);
    }
  }
}

namespace {

constexpr double kMaxCoordinate = 1e6;  // metres: beyond, a point is never kept (nor its cell computed)

/// The cell of a coordinate, its side's inverse given.
std::int64_t cellOf(double coordinate, double inverse_side) {
  return static_cast<std::int64_t>(std::floor(coordinate * inverse_side));
}

std::uint64_t keyOf(std::int64_t cx, std::int64_t cy) {
  // Two's-complement bits of each coordinate, side by side (points are within 1e6 m, so 32 bits each).
  return (static_cast<std::uint64_t>(cx) << 32) ^ (static_cast<std::uint64_t>(cy) & 0xffffffffu);
}

}  // namespace

void LocalMap::resetGrid(std::size_t points) {
  cell_side_ = 2.0 * options_.resolution;
  std::size_t slots = 64;
  while (slots < 2 * points) slots *= 2;
  cell_keys_.assign(slots, 0);
  cell_heads_.assign(slots, -1);
  next_in_cell_.clear();
  remembered_.clear();
}

std::size_t LocalMap::slotOf(std::int64_t cx, std::int64_t cy) const {
  const std::uint64_t key = keyOf(cx, cy);
  const std::size_t mask = cell_keys_.size() - 1;
  std::size_t slot = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 40) & mask;
  while (cell_heads_[slot] >= 0 && cell_keys_[slot] != key) slot = (slot + 1) & mask;
  return slot;
}

bool LocalMap::covered(const Eigen::Vector2d& point) const {
  if (!point.allFinite() || std::abs(point.x()) > kMaxCoordinate || std::abs(point.y()) > kMaxCoordinate) {
    return true;
  }
  const double limit = options_.resolution;
  const double limit_sq = limit * limit;
  // The cells the disc of the resolution touches (a hair wider: rounding never hides a neighbour).
  const double inverse = 1.0 / cell_side_, reach = 1.0001 * limit;
  const std::int64_t x0 = cellOf(point.x() - reach, inverse), x1 = cellOf(point.x() + reach, inverse);
  const std::int64_t y0 = cellOf(point.y() - reach, inverse), y1 = cellOf(point.y() + reach, inverse);
  for (std::int64_t cx = x0; cx <= x1; ++cx) {
    for (std::int64_t cy = y0; cy <= y1; ++cy) {
      for (std::int32_t k = cell_heads_[slotOf(cx, cy)]; k >= 0; k = next_in_cell_[k]) {
        if ((remembered_[k] - point).squaredNorm() < limit_sq) return true;
      }
    }
  }
  return false;
}

void LocalMap::remember(const Eigen::Vector2d& point) {
  if (!point.allFinite() || std::abs(point.x()) > kMaxCoordinate || std::abs(point.y()) > kMaxCoordinate)
    return;
  const double inverse = 1.0 / cell_side_;
  const std::int64_t cx = cellOf(point.x(), inverse), cy = cellOf(point.y(), inverse);
  const std::size_t slot = slotOf(cx, cy);
  cell_keys_[slot] = keyOf(cx, cy);
  next_in_cell_.push_back(cell_heads_[slot]);
  cell_heads_[slot] = static_cast<std::int32_t>(remembered_.size());
  remembered_.push_back(point);
}

}  // namespace hglasm
