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
  transformPoints(points, pose, &moved_);
  // A keyframe is never thinned by its own points (its beams keep their spacing), only by older ones':
  // where keyframes overlap the oldest view stays, so the map holds its shape while the robot moves
  // through it instead of following the newest keyframe's error.
  const double cell_size = 2.0 * options_.resolution;
  covered_.assign(points.size(), 0);
  if (options_.resolution > 0.0) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      covered_[i] = !onGrid(moved_[i]) || submap->grid.anyWithin(moved_[i], options_.resolution, cell_size);
    }
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
      if (onGrid(point)) submap->grid.add(point, cell_size);
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

void LocalMap::PointGrid::clear() {
  slots_.clear();
  points_.clear();
  next_.clear();
  used_ = 0;
}

std::uint64_t LocalMap::PointGrid::keyOf(std::int64_t cx, std::int64_t cy) {
  // Two's-complement bits of each coordinate, side by side (points are within 1e6 m, so 32 bits each).
  return (static_cast<std::uint64_t>(cx) << 32) ^ (static_cast<std::uint64_t>(cy) & 0xffffffffu);
}

int LocalMap::PointGrid::headOf(std::uint64_t key) const {
  if (slots_.empty()) return -1;
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t i = (key * 0x9E3779B97F4A7C15ull) >> 40 & mask;; i = (i + 1) & mask) {
    if (slots_[i].head < 0) return -1;
    if (slots_[i].key == key) return slots_[i].head;
  }
}

void LocalMap::PointGrid::grow() {
  std::vector<Slot> old;
  old.swap(slots_);
  slots_.assign(std::max<std::size_t>(64, 2 * old.size()), Slot());
  const std::size_t mask = slots_.size() - 1;
  for (const Slot& slot : old) {
    if (slot.head < 0) continue;
    std::size_t i = (slot.key * 0x9E3779B97F4A7C15ull) >> 40 & mask;
    while (slots_[i].head >= 0) i = (i + 1) & mask;
    slots_[i] = slot;
  }
}

void LocalMap::PointGrid::add(const Eigen::Vector2d& point, double cell_size) {
  if (2 * (used_ + 1) > slots_.size()) grow();
  const std::uint64_t key = keyOf(static_cast<std::int64_t>(std::floor(point.x() / cell_size)),
                                  static_cast<std::int64_t>(std::floor(point.y() / cell_size)));
  const std::size_t mask = slots_.size() - 1;
  std::size_t i = (key * 0x9E3779B97F4A7C15ull) >> 40 & mask;
  while (slots_[i].head >= 0 && slots_[i].key != key) i = (i + 1) & mask;
  if (slots_[i].head < 0) {
    slots_[i].key = key;
    ++used_;
  }
  next_.push_back(slots_[i].head);
  slots_[i].head = static_cast<int>(points_.size());
  points_.push_back(point);
}

bool LocalMap::PointGrid::anyWithin(const Eigen::Vector2d& point, double radius, double cell_size) const {
  const double fx = point.x() / cell_size, fy = point.y() / cell_size;
  const std::int64_t cx = static_cast<std::int64_t>(std::floor(fx));
  const std::int64_t cy = static_cast<std::int64_t>(std::floor(fy));
  // The disk reaches the neighbouring cell on the side of the cell's centre it lies on.
  const std::int64_t nx = fx - static_cast<double>(cx) < 0.5 ? cx - 1 : cx + 1;
  const std::int64_t ny = fy - static_cast<double>(cy) < 0.5 ? cy - 1 : cy + 1;
  const double radius_sq = radius * radius;
  for (const std::uint64_t key : {keyOf(cx, cy), keyOf(nx, cy), keyOf(cx, ny), keyOf(nx, ny)}) {
    for (int k = headOf(key); k >= 0; k = next_[k]) {
      if ((points_[k] - point).squaredNorm() < radius_sq) return true;
    }
  }
  return false;
}

}  // namespace hglasm
