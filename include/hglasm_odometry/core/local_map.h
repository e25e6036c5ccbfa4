// The reference scans are matched against: the keyframes of a submap, placed at their estimated poses,
// with the submap's lookup tables grown keyframe by keyframe.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

struct LocalMapOptions {
  /// Keyframes per submap. Two submaps overlap (as Cartographer's): every keyframe goes into both, a new one
  /// starts when the newer holds this many, and the older (the one scans are matched against) is then
  /// dropped, so a scan meets between this many and twice as many keyframes. More keyframes hold the match
  /// to more of the surroundings, so each keyframe's own error adds up less; 1: the last keyframe only.
  int keyframes = 20;
  /// Metres: a submap whose first keyframe is this far from the newest keyframe is dropped (what the robot
  /// no longer sees), once a newer one holds a keyframe.
  double max_distance = 20.0;
  /// Metres: a point this close to a point of an older keyframe of the submap adds nothing and is left out,
  /// so the map costs what the surfaces it holds cost, not what the number of keyframes does, and where
  /// keyframes overlap the scan is matched to the oldest view (the anchor that drifted least). 0 keeps
  /// every point.
  double resolution = 0.03;
  /// Metres: the frame the map is expressed in (the origin of MbICP's metric and of its bearing search) moves
  /// to the newest keyframe once that is this far from it, or when the matched submap changes; in between,
  /// a keyframe only adds its points. 0: every keyframe moves it.
  double reframe_distance = 1.0;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, LocalMapOptions* options) {
  visitor.positiveInteger("local_map/keyframes", &options->keyframes);
  visitor.positiveNumber("local_map/max_distance", &options->max_distance);
  visitor.nonNegativeNumber("local_map/resolution", &options->resolution);
  visitor.nonNegativeNumber("local_map/reframe_distance", &options->reframe_distance);
}

/// Keyframes (points in their laser frame, laser pose in the odometry frame) gathered into submaps, each in
/// its first keyframe's frame with its lookup tables; the matched submap's points are offered in the newest
/// keyframe's frame too (MbICP's reference, whose metric wants the sensor near the origin). Not thread-safe
/// per instance.
class LocalMap {
 public:
  /// `tables`: the lookup tables every submap keeps (e.g. the GA's fine and coarse tables), grown by each
  /// keyframe; they answer queries in frame() (LookupTable::setQueryFrame).
  explicit LocalMap(const LocalMapOptions& options = {}, const std::vector<LookupTableOptions>& tables = {});

  /// Adds a keyframe: `points` in the laser frame, `laser_pose` in the odometry frame.
  void add(const Pose2D& laser_pose, const std::vector<Eigen::Vector2d>& points);
  void clear();

  bool empty() const { return submaps_.empty(); }
  /// Keyframes of the submap scans are matched against.
  std::size_t keyframeCount() const { return submaps_.empty() ? 0 : submaps_.front().keyframes; }
  /// The laser pose (odometry frame) of a recent keyframe, within reframe_distance of the newest: the frame
  /// reference() is expressed in.
  const Pose2D& frame() const { return frame_; }
  /// The matched submap's points in frame(), one scan per keyframe.
  const ReferencePoints& reference() const { return reference_; }
  /// Scans of reference() unchanged by the last add() (same frame, same points): the rest are new. 0 after
  /// a change of frame or of the matched submap.
  std::size_t unchangedScans() const { return unchanged_scans_; }
  /// Lookup table `index` (as given to the constructor) of the matched submap, answering in frame().
  const LookupTable& table(std::size_t index) const;
  std::size_t tableCount() const { return table_options_.size(); }
  const LocalMapOptions& options() const { return options_; }
  /// Changes whenever reference() or frame() may have changed (every add() and clear()): consumers that
  /// copy the map (its display) compare it with the revision they copied.
  std::uint64_t revision() const { return revision_; }

 private:
  /// Points by cells twice the resolution wide, so a disk of the resolution's radius meets at most 2 x 2 of
  /// them; cells in an open-addressing table, each cell's points a linked list.
  class PointGrid {
   public:
    void clear();
    void add(const Eigen::Vector2d& point, double cell_size);
    /// True if a point of the grid lies closer than `radius` (half the cell size) to `point`.
    bool anyWithin(const Eigen::Vector2d& point, double radius, double cell_size) const;

   private:
    struct Slot {
      std::uint64_t key = 0;
      int head = -1;  // newest point of the cell; -1: an empty slot
    };
    static std::uint64_t keyOf(std::int64_t cx, std::int64_t cy);
    int headOf(std::uint64_t key) const;
    void grow();
    std::vector<Slot> slots_;
    std::vector<Eigen::Vector2d> points_;
    std::vector<int> next_;  // per point: the previous point of its cell (-1: none)
    std::size_t used_ = 0;
  };
  struct Submap {
    Pose2D anchor;           // laser pose of its first keyframe, odometry frame: the frame of points
    ReferencePoints points;  // kept points of its keyframes, one scan per keyframe
    std::vector<LookupTable> tables;
    PointGrid grid;  // kept points, for the de-duplication
    int keyframes = 0;
  };
  /// Adds a keyframe's points (in the submap's frame as `pose`) but for those an older keyframe holds.
  void insert(Submap* submap, const Pose2D& laser_pose, const std::vector<Eigen::Vector2d>& points);
  /// Points the de-duplication grid can hold (finite, within 1e6 m; wilder readings are never joined).
  static bool onGrid(const Eigen::Vector2d& point) {
    return std::abs(point.x()) <= 1e6 && std::abs(point.y()) <= 1e6;  // false for NaN
  }
  /// reference() and the tables' query frame after the matched submap or frame() changed.
  void refresh();
  /// Appends to reference() what the last insert kept in the matched submap (frame() unchanged).
  void appendNewest();

  LocalMapOptions options_;
  std::vector<LookupTableOptions> table_options_;
  std::deque<Submap> submaps_;  // oldest (matched) first, at most two
  Pose2D frame_;
  ReferencePoints reference_;
  std::uint64_t revision_ = 0;
  std::size_t unchanged_scans_ = 0;
  LookupTable empty_table_;
  ReferencePoints added_;               // scratch: the keyframe's kept points as one scan
  std::vector<Eigen::Vector2d> kept_;   // scratch: in the keyframe's frame
  std::vector<std::uint8_t> covered_;   // scratch: per point of the keyframe, an older keyframe has it
  std::vector<Eigen::Vector2d> moved_;  // scratch: the keyframe's points in the submap's frame
};

}  // namespace hglasm
