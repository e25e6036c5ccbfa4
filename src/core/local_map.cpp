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
  cells_.clear();
  if (keyframes_.empty()) return;
  frame_ = keyframes_.back().laser_pose;
  const Pose2D to_frame = frame_.inverse();
  // Oldest first: where keyframes overlap, the oldest view stays, so the map holds its shape while the
  // robot moves through it instead of following the newest keyframe's error.
  for (const Keyframe& keyframe : keyframes_) {
    const Pose2D pose = to_frame * keyframe.laser_pose;
    // A keyframe is never thinned by its own points (its beams keep their spacing), only by other keyframes'.
    const std::size_t first = reference_.size();
    const std::vector<Eigen::Vector2d>& points = keyframe.points;
    covered_.assign(points.size(), 0);
    if (options_.resolution > 0.0) {
      for (std::size_t i = 0; i < points.size(); ++i) covered_[i] = covered(pose * points[i]);
    }
    // A kept point keeps its neighbouring beams too, covered or not: the surface it lies on stays a surface
    // (alone, a thinned wall's survivors would be isolated points, precise along their beams, which along
    // a corridor's wall is the direction nothing observes).
    kept_.clear();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const bool neighbour_kept = (i > 0 && !covered_[i - 1]) || (i + 1 < points.size() && !covered_[i + 1]);
      if (!covered_[i] || neighbour_kept) kept_.push_back(points[i]);
    }
    reference_.append(kept_, pose);
    if (options_.resolution > 0.0) {
      for (std::size_t i = first; i < reference_.size(); ++i) remember(reference_.points[i]);
    }
  }
}

std::uint64_t LocalMap::cellKey(const Eigen::Vector2d& point, int dx, int dy) const {
  const double inverse = 1.0 / options_.resolution;
  const std::int64_t cx = static_cast<std::int64_t>(std::floor(point.x() * inverse)) + dx;
  const std::int64_t cy = static_cast<std::int64_t>(std::floor(point.y() * inverse)) + dy;
  // Two's-complement bits of each coordinate, side by side (points are within 1e6 m, so 32 bits each).
  return (static_cast<std::uint64_t>(cx) << 32) ^ (static_cast<std::uint64_t>(cy) & 0xffffffffu);
}

bool LocalMap::covered(const Eigen::Vector2d& point) const {
  if (!point.allFinite() || std::abs(point.x()) > 1e6 || std::abs(point.y()) > 1e6) return true;
  const double limit_sq = options_.resolution * options_.resolution;
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      const auto it = cells_.find(cellKey(point, dx, dy));
      if (it == cells_.end()) continue;
      for (const auto& other : it->second) {
        if ((other - point).squaredNorm() < limit_sq) return true;
      }
    }
  }
  return false;
}

void LocalMap::remember(const Eigen::Vector2d& point) { cells_[cellKey(point, 0, 0)].push_back(point); }

}  // namespace hglasm
