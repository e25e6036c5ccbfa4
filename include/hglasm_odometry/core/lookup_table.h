// GLASM lookup tables: a sparse (tiled) 8-bit grid around the reference scan's points.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

enum class TableKind {
  kGraded,  ///< GLASM-g: 255 * exp(-d^2 / (2 sigma^2)) of the distance d to the nearest reference point
  kBinary,  ///< GLASM: 1 inside a square of half-side `sigma` around each reference point
};

struct LookupTableOptions {
  TableKind kind = TableKind::kGraded;
  double cell_size = 0.02;  ///< metres
  double sigma = 0.10;      ///< metres: graded spread; half-side of the binary square
  double cutoff = 0.30;     ///< metres: graded cells farther than this from every reference point hold 0
  /// Consecutive reference points closer than segment_max_gap + segment_gap_per_metre * range are joined:
  /// the table then holds the distance to the scanned surface, not just to its (sparse, far) samples.
  /// segment_max_gap <= 0 turns this off (the papers' point-only table).
  double segment_max_gap = 0.30;  ///< metres
  double segment_gap_per_metre = 0.10;
};

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
  explicit LookupTable(const LookupTableOptions& options = {});

  /// Rebuilds the table for new reference points given in beam order (reusing memory). Non-finite points
  /// are ignored.
  void build(const std::vector<Eigen::Vector2d>& reference);

  /// Cell value at a point in the reference frame; 0 outside the table.
  std::uint8_t valueAt(const Eigen::Vector2d& point) const;

  /// GLASM fitness: sum of the cells hit by `points` moved by `pose`.
  std::uint32_t fitness(const std::vector<Eigen::Vector2d>& points, const Pose2D& pose) const;
  std::uint32_t fitness(const FitnessPoints& points, const Pose2D& pose) const;

  /// Value of a cell hit exactly (255 graded, 1 binary): fitness / (maxCellValue * n) is in [0, 1].
  std::uint32_t maxCellValue() const;

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

  void buildKernel();

  LookupTableOptions options_;
  double inv_cell_size_ = 0.0;
  long origin_cell_x_ = 0;  // global cell coordinates of the first cell of tile_index_[0]
  long origin_cell_y_ = 0;
  long tiles_x_ = 0;
  long tiles_y_ = 0;
  std::vector<std::int32_t> tile_index_;  // tiles_x_ * tiles_y_, -1 = no tile
  std::vector<std::uint8_t> tile_cells_;  // tiles_in_use_ * kTileCells
  std::size_t tiles_in_use_ = 0;
  std::vector<Eigen::Vector2d> samples_;   // scratch: stamp centres
  std::vector<std::uint8_t> kernel_;      // (2r+1)^2 stamp, r = ceil(cutoff / cell_size)
  int kernel_radius_ = 0;
};

}  // namespace hglasm
