// The reference scans are matched against: the last keyframes, placed at their estimated poses.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

struct LocalMapOptions {
  /// Keyframes in the map (1: match against the last keyframe only). More keyframes hold a scan's match to
  /// more of the surroundings, so each keyframe's own error adds up less (at low scan rates every scan is a
  /// keyframe); they cost association time.
  int keyframes = 7;
  /// Metres: a keyframe this far from the newest one leaves the map (what the robot no longer sees).
  double max_distance = 20.0;
  /// Metres: a point this close to a point of an older keyframe adds nothing and is left out, so the map
  /// costs what the surfaces it holds cost, not what the number of keyframes does, and where keyframes
  /// overlap the scan is matched to the oldest view (the anchor that drifted least). 0 keeps every point.
  double resolution = 0.03;
};

/// Keyframes (points in their laser frame, laser pose in the odometry frame) and their union in the
/// newest keyframe's frame, rebuilt when a keyframe comes or goes. Not thread-safe per instance.
class LocalMap {
 public:
  explicit LocalMap(const LocalMapOptions& options = {});

  /// Adds a keyframe: `points` in the laser frame, `laser_pose` in the odometry frame. Drops the oldest
  /// keyframes beyond the options' count or distance.
  void add(const Pose2D& laser_pose, const std::vector<Eigen::Vector2d>& points);
  void clear();

  bool empty() const { return keyframes_.empty(); }
  std::size_t keyframeCount() const { return keyframes_.size(); }
  /// The newest keyframe's laser pose in the odometry frame: the frame reference() is expressed in.
  const Pose2D& frame() const { return frame_; }
  /// Every keyframe's points in frame(), one scan per keyframe.
  const ReferencePoints& reference() const { return reference_; }
  const LocalMapOptions& options() const { return options_; }
  /// Changes whenever reference() or frame() may have changed (every add() and clear()): consumers that
  /// copy the map (its display) compare it with the revision they copied.
  std::uint64_t revision() const { return revision_; }

 private:
  struct Keyframe {
    Pose2D laser_pose;
    std::vector<Eigen::Vector2d> points;
  };
  void rebuild();
  /// True if a point of a keyframe added before lies within options_.resolution of `point`.
  bool covered(const Eigen::Vector2d& point) const;
  void remember(const Eigen::Vector2d& point);
  /// Empties the grid of remembered points, sized for up to `points` of them.
  void resetGrid(std::size_t points);
  /// The grid's slot of a cell: where it is, or the empty slot where it would go.
  std::size_t slotOf(std::int64_t cx, std::int64_t cy) const;

  LocalMapOptions options_;
  std::deque<Keyframe> keyframes_;  // oldest first
  Pose2D frame_;
  ReferencePoints reference_;
  std::uint64_t revision_ = 0;
  // Scratch of rebuild(): kept points by grid cell (side twice the resolution, so the points within the
  // resolution of any point lie in at most 2 x 2 cells), an open-addressing table of cells, each the head
  // of a list of its points.
  double cell_side_ = 0.0;
  std::vector<std::uint64_t> cell_keys_;
  std::vector<std::int32_t> cell_heads_;  // -1: empty slot
  std::vector<std::int32_t> next_in_cell_;
  std::vector<Eigen::Vector2d> remembered_;
  std::vector<Eigen::Vector2d> moved_;  // the keyframe's points in frame()
  std::vector<Eigen::Vector2d> kept_;   // those kept
  std::vector<std::uint8_t> covered_;   // per point of the keyframe being added: an older keyframe has it
};

}  // namespace hglasm
