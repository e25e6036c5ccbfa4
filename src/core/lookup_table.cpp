#include "hglasm_odometry/core/lookup_table.h"

#include <algorithm>
#include <cmath>

namespace hglasm {

LookupTable::LookupTable(const LookupTableOptions& options) : options_(options) {
  // Guard against nonsense sizes here too; the ROS layer validates and names the parameter.
  if (!(options_.cell_size > 1e-4)) options_.cell_size = LookupTableOptions().cell_size;
  if (!(options_.sigma > 0.0)) options_.sigma = LookupTableOptions().sigma;
  if (!(options_.cutoff >= options_.cell_size))
    options_.cutoff = std::max(options_.cell_size, 3 * options_.sigma);
  inv_cell_size_ = 1.0 / options_.cell_size;
  buildKernel();
}

void LookupTable::buildKernel() {
  // The stamp around one reference point, precomputed once: the value of a cell is the likelihood of
  // the distance from the reference point's cell centre to this cell's centre.
  const double reach = options_.kind == TableKind::kGraded ? options_.cutoff : options_.sigma;
  kernel_radius_ = static_cast<int>(std::ceil(reach * inv_cell_size_ - 1e-9));
  const int side = 2 * kernel_radius_ + 1;
  kernel_.assign(static_cast<std::size_t>(side) * side, 0);
  const double inv_two_sigma_sq = 1.0 / (2.0 * options_.sigma * options_.sigma);
  for (int dy = -kernel_radius_; dy <= kernel_radius_; ++dy) {
    for (int dx = -kernel_radius_; dx <= kernel_radius_; ++dx) {
      std::uint8_t value = 0;
      if (options_.kind == TableKind::kGraded) {
        const double distance = std::hypot(dx, dy) * options_.cell_size;
        if (distance <= options_.cutoff) {
          value = static_cast<std::uint8_t>(
              std::lround(255.0 * std::exp(-distance * distance * inv_two_sigma_sq)));
        }
      } else {
        value = 1;  // the whole square
      }
      kernel_[(dy + kernel_radius_) * side + dx + kernel_radius_] = value;
    }
  }
  kernel_spans_.assign(static_cast<std::size_t>(side), {0, 0});
  for (int row = 0; row < side; ++row) {
    const std::uint8_t* values = &kernel_[static_cast<std::size_t>(row) * side];
    int first = 0, last = side;
    while (first < side && values[first] == 0) ++first;
    while (last > first && values[last - 1] == 0) --last;
    kernel_spans_[row] = {first, last};
  }
}

std::uint32_t LookupTable::maxCellValue() const { return options_.kind == TableKind::kGraded ? 255u : 1u; }

std::size_t LookupTable::memoryBytes() const {
  return tile_offset_.capacity() * sizeof(std::int32_t) + tile_cells_.capacity() + stamped_.capacity() +
         kernel_.capacity();
}

void LookupTable::build(const std::vector<Eigen::Vector2d>& reference) {
  ReferencePoints single;
  single.append(reference);
  build(single);
}

void LookupTable::stampFootprints(const ReferencePoints& reference, const std::vector<std::uint8_t>& joins,
                                  double spacing) {
  for (std::size_t scan = 0; scan < reference.scan_starts.size(); ++scan) {
    const std::size_t begin = reference.scan_starts[scan], end = reference.scanEnd(scan);
    const Eigen::Vector2d origin = reference.scanOrigin(scan);
    const double step = angularStep(reference, scan);
    for (std::size_t i = begin; i < end; ++i) {
      const Eigen::Vector2d& p = reference.points[i];
      const bool isolated = !(i > begin && joins[i - 1]) && !joins[i];
      if (!isolated || !withinTable(p)) continue;
      const Eigen::Vector2d beam = p - origin;
      // Capped: a scan of a few points has no meaningful angular step.
      const double half_width =
          std::min(0.5 * options_.isolated_footprint * step * beam.norm(), kMaxFootprint);
      if (!(half_width > spacing) || !(beam.norm() > 0.0)) continue;
      const Eigen::Vector2d across = Eigen::Vector2d(-beam.y(), beam.x()).normalized();
      const int pieces = static_cast<int>(std::ceil(half_width / spacing));
      for (int k = 1; k <= pieces; ++k) {
        samples_.push_back(p + across * (half_width * k / pieces));
        samples_.push_back(p - across * (half_width * k / pieces));
      }
    }
  }
}

void LookupTable::collectSamples(const ReferencePoints& reference_set) {
  const std::vector<Eigen::Vector2d>& reference = reference_set.points;
  // Stamp centres: the points, plus samples along short gaps between consecutive points, spaced so that
  // every point of the segment is within a quarter sigma of a sample.
  samples_.clear();
  const double spacing = std::max(options_.cell_size, 0.5 * options_.sigma);
  const std::vector<std::uint8_t> joins = joinSurfaces(reference_set, options_.surface());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Eigen::Vector2d& p = reference[i];
    // Points beyond kMaxCoordinate get no cell (below); they must not be joined either: the joining gap
    // grows with the range, and two wild readings 1e30 m out would be joined by billions of samples.
    if (!withinTable(p)) continue;
    samples_.push_back(p);
    if (i + 1 < reference.size() && joins[i] && withinTable(reference[i + 1])) {
      const Eigen::Vector2d& next = reference[i + 1];
      const double gap = (next - p).norm();
      const int pieces = static_cast<int>(std::ceil(gap / spacing));
      for (int k = 1; k < pieces; ++k) samples_.push_back(p + (next - p) * (double(k) / pieces));
    }
  }
  if (options_.isolated_footprint > 0.0) stampFootprints(reference_set, joins, spacing);
}

bool LookupTable::collectCells(const ReferencePoints& reference_set, Box* box) {
  collectSamples(reference_set);
  cells_.clear();
  for (const auto& p : samples_) {
    if (std::abs(p.x()) > kMaxCoordinate || std::abs(p.y()) > kMaxCoordinate) continue;
    const long cx = static_cast<long>(std::floor(p.x() * inv_cell_size_));
    const long cy = static_cast<long>(std::floor(p.y() * inv_cell_size_));
    if (cells_.empty()) {
      box->min_x = box->max_x = cx;
      box->min_y = box->max_y = cy;
    } else {
      box->min_x = std::min(box->min_x, cx), box->max_x = std::max(box->max_x, cx);
      box->min_y = std::min(box->min_y, cy), box->max_y = std::max(box->max_y, cy);
    }
    cells_.emplace_back(cx, cy);
  }
  return !cells_.empty();
}

void LookupTable::allocateTiles(const Box& box) {
  // Tile grid covering the box grown by the kernel radius, inside a ring of zero tiles (lookups clamped
  // onto the ring read zero); only touched tiles get cells, the others share the zero tile.
  const long r = kernel_radius_;
  const auto floor_div = [](long a) {
    return a >= 0 ? a >> kTileShift : -((-a + kTileSize - 1) >> kTileShift);
  };
  const long first_tile_x = floor_div(box.min_x - r), last_tile_x = floor_div(box.max_x + r);
  const long first_tile_y = floor_div(box.min_y - r), last_tile_y = floor_div(box.max_y + r);
  tiles_x_ = last_tile_x - first_tile_x + 1;
  tiles_y_ = last_tile_y - first_tile_y + 1;
  origin_cell_x_ = first_tile_x * kTileSize;
  origin_cell_y_ = first_tile_y * kTileSize;
  stride_shift_ = 0;
  while ((1L << stride_shift_) < tiles_x_ + 2) ++stride_shift_;
  tile_offset_.assign(static_cast<std::size_t>((tiles_y_ + 2) << stride_shift_), -1);
  for (const auto& cell : cells_) {
    const long lx0 = cell.first - r - origin_cell_x_, lx1 = cell.first + r - origin_cell_x_;
    const long ly0 = cell.second - r - origin_cell_y_, ly1 = cell.second + r - origin_cell_y_;
    for (long ty = ly0 >> kTileShift; ty <= (ly1 >> kTileShift); ++ty) {
      for (long tx = lx0 >> kTileShift; tx <= (lx1 >> kTileShift); ++tx) {
        std::int32_t& offset = tile_offset_[tileSlot(tx << kTileShift, ty << kTileShift, stride_shift_)];
        if (offset < 0) offset = static_cast<std::int32_t>(tiles_in_use_++ * kTileCells);
      }
    }
  }
  const auto zero_tile = static_cast<std::int32_t>(tiles_in_use_ * kTileCells);
  for (std::int32_t& offset : tile_offset_) {
    if (offset < 0) offset = zero_tile;
  }
  tile_cells_.assign((tiles_in_use_ + 1) * kTileCells, 0);
}

void LookupTable::build(const ReferencePoints& reference_set) {
  tiles_in_use_ = 0;
  tiles_x_ = tiles_y_ = 0;
  tile_offset_.clear();
  Box box;
  if (!collectCells(reference_set, &box)) return;
  allocateTiles(box);

  // Stamp the kernel around each point, keeping the maximum (likelihood of the nearest point). A stamp
  // depends on the centre's cell only: overlapping keyframes and close samples put many in one cell, which
  // is stamped once.
  stamped_.assign(tiles_in_use_ * kTileCells, 0);
  const long r = kernel_radius_;
  const long side = 2 * r + 1;
  for (const auto& cell : cells_) {
    const long cx = cell.first - origin_cell_x_, cy = cell.second - origin_cell_y_;
    std::uint8_t& centre = stamped_[cellOffset(cx, cy)];
    if (centre) continue;
    centre = 1;
    const long lx0 = cx - r;
    const long ly0 = cy - r;
    for (long ky = 0; ky < side; ++ky) {
      const long ly = ly0 + ky;
      const std::int32_t* offset_row = &tile_offset_[tileSlot(0, ly, stride_shift_)];
      const std::uint8_t* kernel_row = &kernel_[ky * side];
      const long cell_row = (ly & (kTileSize - 1)) << kTileShift;
      // The row's non-zero span, in runs that stay within one tile: contiguous bytes the compiler
      // vectorises.
      const long end = kernel_spans_[ky].second;
      for (long kx = kernel_spans_[ky].first; kx < end;) {
        const long lx = lx0 + kx;
        const long in_tile = lx & (kTileSize - 1);
        const long run = std::min(end - kx, kTileSize - in_tile);
        std::uint8_t* target = &tile_cells_[offset_row[lx >> kTileShift] + cell_row + in_tile];
        const std::uint8_t* value = kernel_row + kx;
        for (long i = 0; i < run; ++i) target[i] = std::max(target[i], value[i]);
        kx += run;
      }
    }
  }
}

std::uint8_t LookupTable::valueAt(const Eigen::Vector2d& point) const {
  if (tiles_in_use_ == 0) return 0;
  const double fx = point.x() * inv_cell_size_ - origin_cell_x_;
  const double fy = point.y() * inv_cell_size_ - origin_cell_y_;
  if (!(fx >= 0.0 && fy >= 0.0 && fx < tiles_x_ * kTileSize && fy < tiles_y_ * kTileSize)) return 0;
  return tile_cells_[cellOffset(static_cast<long>(fx), static_cast<long>(fy))];
}

int LookupTable::beamsThroughSurfaces(const std::vector<Eigen::Vector2d>& points, const Pose2D& sensor,
                                      double margin) const {
  if (tiles_in_use_ == 0 || !sensor.isFinite()) return 0;
  // Steps of one cell: a graded surface's band (value >= max / 2) is 2.4 sigma wide, a binary one a cell.
  const double step = 1.0 / inv_cell_size_;
  const auto surface = static_cast<std::uint8_t>(std::max<std::uint32_t>(1, maxCellValue() / 2));
  const Eigen::Vector2d origin = sensor.translation();
  int through = 0;
  for (const Eigen::Vector2d& point : points) {
    const double range = point.norm();
    if (!std::isfinite(range) || range <= 2.0 * margin) continue;
    const Eigen::Vector2d direction = (sensor * point - origin) / range;
    for (double r = margin; r < range - margin; r += step) {
      if (valueAt(origin + r * direction) >= surface) {
        ++through;
        break;
      }
    }
  }
  return through;
}

void FitnessPoints::assign(const std::vector<Eigen::Vector2d>& points) {
  x.clear();
  y.clear();
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    x.push_back(static_cast<float>(p.x()));
    y.push_back(static_cast<float>(p.y()));
  }
}

std::uint32_t LookupTable::fitness(const std::vector<Eigen::Vector2d>& points, const Pose2D& pose) const {
  FitnessPoints prepared;
  prepared.assign(points);
  return fitness(prepared, pose);
}

std::uint32_t LookupTable::fitness(const FitnessPoints& points, const Pose2D& pose) const {
  std::uint32_t sum = 0;
  forEachCell(points, pose, [&sum](std::uint8_t value) { sum += value; });
  return sum;
}

double LookupTable::logLikelihood(const FitnessPoints& points, const Pose2D& pose, double outlier) const {
  if (points.size() == 0) return 0.0;
  std::uint32_t counts[256] = {};
  std::uint32_t on_table = 0;
  forEachCell(points, pose, [&](std::uint8_t value) {
    ++counts[value];
    ++on_table;
  });
  counts[0] += static_cast<std::uint32_t>(points.size()) - on_table;  // off the table: no reference near
  const double max_value = static_cast<double>(maxCellValue());
  double sum = 0.0;
  for (int value = 0; value < 256; ++value) {
    if (counts[value]) sum += counts[value] * std::log(outlier + value / max_value);
  }
  return sum;
}

}  // namespace hglasm
