#include "hglasm_odometry/core/local_map.h"

#include <algorithm>
#include <cmath>

namespace hglasm {

LocalMap::LocalMap(const LocalMapOptions& options, const std::vector<LookupTableOptions>& tables)
    : options_(options), table_options_(tables) {
  options_.keyframes = std::max(1, options_.keyframes);
}

void LocalMap::add(const Pose2D& laser_pose, const std::vector<Eigen::Vector2d>& points) {
  ++revision_;
  // A new submap starts when the newer one is full; the older (matched) one goes when a third would start.
  bool matched_changed = submaps_.empty();
  if (submaps_.empty() || submaps_.back().keyframes >= options_.keyframes) {
    if (submaps_.size() >= 2) {
      submaps_.pop_front();
      matched_changed = true;
    }
    submaps_.emplace_back();
    Submap& started = submaps_.back();
    started.anchor = laser_pose;
    for (const LookupTableOptions& table : table_options_) started.tables.emplace_back(table);
  }
  const std::size_t matched_scans = submaps_.front().points.scan_starts.size();
  for (Submap& submap : submaps_) insert(&submap, laser_pose, points);
  while (submaps_.size() > 1 &&
         (submaps_.front().anchor.translation() - laser_pose.translation()).norm() > options_.max_distance) {
    submaps_.pop_front();
    matched_changed = true;
  }
  // MbICP's metric wants the sensor near the frame's origin: the frame follows the keyframes, but only
  // every reframe_distance, so that most keyframes extend the reference instead of rebuilding it.
  const bool reframe = matched_changed || !(options_.reframe_distance > 0.0) ||
                       (laser_pose.translation() - frame_.translation()).norm() >= options_.reframe_distance;
  if (reframe) {
    frame_ = laser_pose;
    refresh();
    unchanged_scans_ = 0;
  } else {
    unchanged_scans_ = reference_.scan_starts.size();
    if (submaps_.front().points.scan_starts.size() > matched_scans) appendNewest();
  }
}

void LocalMap::clear() {
  submaps_.clear();
  reference_.clear();
  unchanged_scans_ = 0;
  frame_ = Pose2D();
  ++revision_;
}

const LookupTable& LocalMap::table(std::size_t index) const {
  if (submaps_.empty() || index >= submaps_.front().tables.size()) return empty_table_;
  return submaps_.front().tables[index];
}

void LocalMap::insert(Submap* submap, const Pose2D& laser_pose, const std::vector<Eigen::Vector2d>& points) {
  const Pose2D pose = submap->anchor.inverse() * laser_pose;
  // A keyframe is never thinned by its own points (its beams keep their spacing), only by older ones':
  // where keyframes overlap the oldest view stays, so the map holds its shape while the robot moves
  // through it instead of following the newest keyframe's error.
  covered_.assign(points.size(), 0);
  if (options_.resolution > 0.0) {
    for (std::size_t i = 0; i < points.size(); ++i) covered_[i] = covered(*submap, pose * points[i]);
  }
  // A kept point keeps its neighbouring beams too, covered or not: the surface it lies on stays a surface
  // (alone, a thinned wall's survivors would be isolated points, precise along their beams, which along a
  // corridor's wall is the direction nothing observes).
  kept_.clear();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const bool neighbour_kept = (i > 0 && !covered_[i - 1]) || (i + 1 < points.size() && !covered_[i + 1]);
    if (!covered_[i] || neighbour_kept) kept_.push_back(points[i]);
  }
  added_.clear();
  added_.append(kept_, pose);
  submap->points.append(kept_, pose);
  if (options_.resolution > 0.0) {
    for (const Eigen::Vector2d& point : added_.points) {
      if (onGrid(point)) submap->cells[cellKey(point, 0, 0)].push_back(point);
    }
  }
  for (LookupTable& table : submap->tables) table.insert(added_);
  ++submap->keyframes;
}

void LocalMap::refresh() {
  reference_.clear();
  if (submaps_.empty()) return;
  Submap& matched = submaps_.front();
  const Pose2D to_frame = frame_.inverse() * matched.anchor;
  const ReferencePoints& points = matched.points;
  transformPoints(points.points, to_frame, &reference_.points);
  reference_.scan_starts = points.scan_starts;
  reference_.scan_steps = points.scan_steps;  // angles between beams: the same in any frame
  for (const Eigen::Vector2d& origin : points.scan_origins)
    reference_.scan_origins.push_back(to_frame * origin);
  const Pose2D query_in_table = to_frame.inverse();
  for (LookupTable& table : matched.tables) table.setQueryFrame(query_in_table);
}

void LocalMap::appendNewest() {
  const Submap& matched = submaps_.front();
  const ReferencePoints& points = matched.points;
  const std::size_t scan = points.scan_starts.size() - 1;
  const Pose2D to_frame = frame_.inverse() * matched.anchor;
  const std::size_t start = points.scan_starts[scan];
  kept_.assign(points.points.begin() + static_cast<std::ptrdiff_t>(start), points.points.end());
  transformPoints(kept_, to_frame, &added_.points);
  reference_.appendMoved(added_.points, to_frame * points.scanOrigin(scan));
  // The step as refresh() copies it (the same angle, computed once in the submap's frame).
  if (scan < points.scan_steps.size() && reference_.scan_steps.size() == reference_.scan_starts.size()) {
    reference_.scan_steps.back() = points.scan_steps[scan];
  }
}

std::uint64_t LocalMap::cellKey(const Eigen::Vector2d& point, int dx, int dy) const {
  const double inverse = 1.0 / options_.resolution;
  const std::int64_t cx = static_cast<std::int64_t>(std::floor(point.x() * inverse)) + dx;
  const std::int64_t cy = static_cast<std::int64_t>(std::floor(point.y() * inverse)) + dy;
  // Two's-complement bits of each coordinate, side by side (points are within 1e6 m, so 32 bits each).
  return (static_cast<std::uint64_t>(cx) << 32) ^ (static_cast<std::uint64_t>(cy) & 0xffffffffu);
}

bool LocalMap::covered(const Submap& submap, const Eigen::Vector2d& point) const {
  if (!onGrid(point)) return true;
  const double limit_sq = options_.resolution * options_.resolution;
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      const auto it = submap.cells.find(cellKey(point, dx, dy));
      if (it == submap.cells.end()) continue;
      for (const auto& other : it->second) {
        if ((other - point).squaredNorm() < limit_sq) return true;
      }
    }
  }
  return false;
}

}  // namespace hglasm
