// GLASM lookup tables: a sparse (tiled) 8-bit grid around the reference scan's points.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

struct LookupTableOptions {
  /// metres; measured with the success_ratio tool (README): 4 cm cells cost no success against 2 cm and
  /// halve the table build
  double cell_size = 0.04;
  double sigma = 0.10;   ///< metres: spread of the graded values
  double cutoff = 0.30;  ///< metres: graded cells farther than this from every reference point hold 0
  /// Consecutive reference points of one surface (SurfaceOptions: within segment_max_gap, or the gap a
  /// surface seen at up to segment_max_incidence leaves between beams) are joined: the table then holds
  /// the distance to the scanned surface, not just to its (sparse, far) samples. segment_max_gap <= 0
  /// turns this off (the papers' point-only table).
  double segment_max_gap = 0.30;                      ///< metres
  double segment_max_incidence = 1.3962634015954636;  ///< radians (80 degrees)
  /// An isolated reference point (joined to neither neighbour) stands for the surface its beam hit, which
  /// lies anywhere within the beam's angular cell: it is stamped as a short line across its beam, this
  /// fraction of the scan's angular step wide (range * step * footprint). A far sparse point then scores a
  /// new point that sampled the same surface a little to its side, as a joined surface would. 0: a point.
  double isolated_footprint = 1.0;
  SurfaceOptions surface() const { return SurfaceOptions{segment_max_gap, segment_max_incidence}; }
};

/// Its parameters under `prefix` ("table/", "coarse_table/") with their valid ranges, for OptionReader and
/// OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, const std::string& prefix, LookupTableOptions* options) {
  visitor.positiveNumber(prefix + "cell_size", &options->cell_size);
  visitor.positiveNumber(prefix + "sigma", &options->sigma);
  visitor.positiveNumber(prefix + "cutoff", &options->cutoff);
  visitor.number(prefix + "segment_max_gap", &options->segment_max_gap, 0.0,
                 std::numeric_limits<double>::infinity());
  visitor.number(prefix + "segment_max_incidence", &options->segment_max_incidence, 0.0, 0.5 * M_PI);
  visitor.nonNegativeNumber(prefix + "isolated_footprint", &options->isolated_footprint);
}

/// The stamp of one reference point: the values of the cells (dx, dy) cells from its cell, |dx|, |dy| <=
/// radius, row by row. Its largest value is the table's maxCellValue().
struct TableKernel {
  int radius = 0;
  std::vector<std::uint8_t> values;  ///< (2 radius + 1)^2
};
/// GLASM-g's stamp, the odometry's: 255 * exp(-d^2 / (2 sigma^2)) of the distance d between the cells'
/// centres, 0 beyond the cutoff.
TableKernel gradedKernel(const LookupTableOptions& options);
/// Makes a table's stamp from its (validated) options.
using TableKernelFunction = TableKernel (*)(const LookupTableOptions& options);

/// Points prepared for repeated fitness evaluation (single precision, structure of arrays, so the
/// transform vectorises). Build once per scan with assign().
struct FitnessPoints {
  std::vector<float> x;
  std::vector<float> y;
  void assign(const std::vector<Eigen::Vector2d>& points);
  std::size_t size() const { return x.size(); }
};

/// Built once per reference scan. Memory is proportional to the area the reference points cover:
/// only tiles of 32 x 32 cells within `cutoff` of a reference point are allocated.
class LookupTable {
 public:
  /// `kernel`: the stamp (graded; the evaluation library's binary GLASM passes its own). A kernel of the
  /// wrong size is replaced by the graded one.
  explicit LookupTable(const LookupTableOptions& options = {}, TableKernelFunction kernel = gradedKernel);

  /// Rebuilds the table for new reference points given in beam order (reusing memory). Non-finite points
  /// are ignored.
  void build(const std::vector<Eigen::Vector2d>& reference);
  /// The same for several scans in one frame (a local map): gaps are joined within a scan only.
  void build(const ReferencePoints& reference);
  /// Adds reference scans (in the table's own frame) to what it holds, stamping only them: a local map that
  /// grows keyframe by keyframe. Cells keep the maximum, so any order of inserts gives build()'s table.
  void insert(const ReferencePoints& scans);
  void clear();
  /// The queries below take poses and points in a frame whose pose in the table's own frame is
  /// `query_in_table` (identity by default): a table kept in a fixed frame serves a moving reference frame.
  void setQueryFrame(const Pose2D& query_in_table) { query_in_table_ = query_in_table; }
  const Pose2D& queryFrame() const { return query_in_table_; }

  /// Log-likelihood of `points` moved by `pose` under the table read as a likelihood field: each point
  /// scores log(outlier + cell / maxCell), a normal of its distance to the reference mixed with a uniform
  /// outlier density, so points far from any reference point cost a bounded amount.
  double logLikelihood(const FitnessPoints& points, const Pose2D& pose, double outlier) const;

  /// How many beams, from the sensor at `sensor` to each of `points` (sensor frame), pass a cell of at least
  /// half the maximum value (a reference surface) farther than `margin` from both of their ends: beams
  /// that see through the reference, which a pose that is right leaves few of.
  int beamsThroughSurfaces(const std::vector<Eigen::Vector2d>& points, const Pose2D& sensor,
                           double margin) const;

  /// Cell value at a point in the reference frame; 0 outside the table.
  std::uint8_t valueAt(const Eigen::Vector2d& point) const;

  /// GLASM fitness: sum of the cells hit by `points` moved by `pose`.
  std::uint32_t fitness(const std::vector<Eigen::Vector2d>& points, const Pose2D& pose) const;
  std::uint32_t fitness(const FitnessPoints& points, const Pose2D& pose) const;

  /// Value of a cell hit exactly (255 graded): fitness / (maxCellValue * n) is in [0, 1].
  std::uint32_t maxCellValue() const { return max_cell_value_; }

  const LookupTableOptions& options() const { return options_; }
  bool empty() const { return tiles_in_use_ == 0; }
  std::size_t tileCount() const { return tiles_in_use_; }
  std::size_t memoryBytes() const;

 private:
  static constexpr int kTileShift = 5;  // 32 x 32 cells per tile
  static constexpr int kTileSize = 1 << kTileShift;
  static constexpr int kTileCells = kTileSize * kTileSize;

  /// Reference coordinates beyond this are ignored, so a wild (but finite) reading cannot blow up the index.
  static constexpr double kMaxCoordinate = 500.0;
  static constexpr double kMaxFootprint = 0.5;  ///< metres: half-width cap of an isolated point's stamp

  static bool withinTable(const Eigen::Vector2d& p) {
    return std::abs(p.x()) <= kMaxCoordinate && std::abs(p.y()) <= kMaxCoordinate;  // false for NaN
  }
  static LookupTableOptions validated(LookupTableOptions options);
  void setKernel(const TableKernel& kernel);
  /// Cell value at a point in the table's own frame; 0 outside the table.
  std::uint8_t valueInTable(const Eigen::Vector2d& point) const;
  struct Box {
    long min_x = 0, max_x = -1, min_y = 0, max_y = -1;
  };
  /// The stamp centres' global cells (cells_) and their bounding box; false if there is none.
  bool collectCells(const ReferencePoints& reference, Box* box);
  /// Widens the tile grid (keeping the tiles it has) to the box grown by the kernel radius, and gives the
  /// cells_' stamps their tiles.
  void allocateTiles(const Box& box);
  /// The grid's first and last tile on each axis for a box of cells.
  Box tileRange(const Box& box) const;
  void regrid(const Box& tiles);
  /// A tile of cells for tile_offset_'s entry `slot` if it has none.
  void allocateTile(long slot);
  /// Maxes the kernel into the cells around table cell (cx, cy).
  void stamp(long cx, long cy);
  void stampWide(long cx, long cy);  // the same for a kernel wider than a tile
  /// Kernel rows [begin, end) of a stamp: kernel column c goes to left[ky * kTileSize + c] before column
  /// `split` (a tile edge), to right[ky * kTileSize + c] from it on.
  void stampRows(long begin, long end, long split, std::uint8_t* left, std::uint8_t* right);
  /// tile_offset_'s entry of the tile holding table cell (x, y), x and y >= -kTileSize (the ring).
  static long tileSlot(long x, long y, int stride_shift) {
    return (((y >> kTileShift) + 1) << stride_shift) + (x >> kTileShift) + 1;
  }
  /// Index into tile_cells_ (or stamped_'s bits) of the cell at table coordinates (x, y), x and y >=
  /// -kTileSize.
  std::size_t cellOffset(long x, long y) const {
    return static_cast<std::size_t>(tile_offset_[tileSlot(x, y, stride_shift_)]) +
           static_cast<std::size_t>(((y & (kTileSize - 1)) << kTileShift) + (x & (kTileSize - 1)));
  }
  /// Stamp centres (samples_): the points, samples along joined gaps and isolated points' footprints.
  void collectSamples(const ReferencePoints& reference);
  /// Adds samples across the beam of each isolated reference point (isolated_footprint).
  void stampFootprints(const ReferencePoints& reference, const std::vector<std::uint8_t>& joins,
                       double spacing);

  /// Calls f(cell value) for every point of `points` moved by `pose` (0 off the table). One transform and
  /// one byte read per point, no branch: the cell scaling is folded into the transform, which runs in
  /// blocks the compiler vectorises; coordinates are clamped into the ring of zero tiles around the table
  /// (NaN -> onto the ring), whose tiles, like every tile without cells, share one tile of zeros.
  template <typename F>
  void forEachCell(const FitnessPoints& points, const Pose2D& query_pose, F&& f) const {
    if (tiles_in_use_ == 0 || !query_pose.isFinite()) return;
    const Pose2D pose = query_in_table_ * query_pose;
    const float c = static_cast<float>(std::cos(pose.theta) * inv_cell_size_);
    const float s = static_cast<float>(std::sin(pose.theta) * inv_cell_size_);
    const float ox = static_cast<float>(pose.x * inv_cell_size_ - origin_cell_x_);
    const float oy = static_cast<float>(pose.y * inv_cell_size_ - origin_cell_y_);
    constexpr float kRing = static_cast<float>(kTileSize);
    const float max_x = static_cast<float>(tiles_x_ * kTileSize) + kRing - 1.0f;
    const float max_y = static_cast<float>(tiles_y_ * kTileSize) + kRing - 1.0f;
    const std::int32_t* offsets = tile_offset_.data();
    const std::uint8_t* cells = tile_cells_.data();
    const int stride_shift = stride_shift_;
    constexpr std::size_t kBlock = 64;
    std::int32_t tile[kBlock], in_tile[kBlock];
    const std::size_t n = points.size();
    const float* px = points.x.data();
    const float* py = points.y.data();
    for (std::size_t begin = 0; begin < n; begin += kBlock) {
      const std::size_t count = std::min(kBlock, n - begin);
      for (std::size_t i = 0; i < count; ++i) {
        const float fx = c * px[begin + i] - s * py[begin + i] + ox;
        const float fy = s * px[begin + i] + c * py[begin + i] + oy;
        const auto lx = static_cast<std::int32_t>(std::min(std::max(-kRing, fx), max_x));
        const auto ly = static_cast<std::int32_t>(std::min(std::max(-kRing, fy), max_y));
        tile[i] = static_cast<std::int32_t>(tileSlot(lx, ly, stride_shift));
        in_tile[i] = ((ly & (kTileSize - 1)) << kTileShift) + (lx & (kTileSize - 1));
      }
      for (std::size_t i = 0; i < count; ++i) f(cells[offsets[tile[i]] + in_tile[i]]);
    }
  }

  LookupTableOptions options_;
  double inv_cell_size_ = 0.0;
  long origin_cell_x_ = 0;  // global cell coordinates of the first cell of tile_index_[0]
  long origin_cell_y_ = 0;
  long tiles_x_ = 0;
  long tiles_y_ = 0;
  /// Rows of 2^stride_shift_ >= tiles_x_ + 2 tiles, tiles_y_ + 2 of them, the ring included: each tile's
  /// first cell in tile_cells_ (the zero tile's where it has no cells).
  std::vector<std::int32_t> tile_offset_;
  int stride_shift_ = 0;
  std::vector<std::uint8_t> tile_cells_;  // tile_slots_ * kTileCells (the zero tile among them), padding
  std::size_t tiles_in_use_ = 0;          // tiles with cells
  std::size_t tile_slots_ = 0;            // tiles in tile_cells_: those and the zero tile
  std::int32_t zero_tile_ = 0;            // the zero tile's first cell in tile_cells_
  Pose2D query_in_table_;
  std::vector<Eigen::Vector2d> samples_;      // scratch: stamp centres
  std::vector<std::pair<long, long>> cells_;  // scratch: their global cells
  std::vector<std::uint64_t>
      stamped_;                       // scratch: a bit per cell of tile_cells_, set where a stamp is centred
  std::vector<std::uint8_t> kernel_;  // (2r+1) rows of kernel_stride_ bytes, r = ceil(cutoff / cell_size)
  long kernel_stride_ = 0;
  std::vector<std::pair<long, long>> kernel_spans_;  // per kernel row: [first, last) non-zero columns
  std::pair<long, long> kernel_rows_;                // [first, last) rows with a non-zero column
  int kernel_radius_ = 0;
  std::uint32_t max_cell_value_ = 1;
};

}  // namespace hglasm
