#include "hglasm_odometry/core/lookup_table.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace hglasm {
namespace {

constexpr long kChunk = 16;

/// Byte masks: kLeadingBytes[n] has its first n bytes set.
struct LeadingBytes {
  std::uint8_t mask[kChunk + 1][kChunk];
  constexpr LeadingBytes() : mask() {
    for (long n = 0; n <= kChunk; ++n) {
      for (long i = 0; i < kChunk; ++i) mask[n][i] = i < n ? 0xFF : 0x00;
    }
  }
};
constexpr LeadingBytes kLeadingBytes;

/// target[i] = max(target[i], values[i] & mask[i]) for i < kChunk, one operation the compiler vectorises.
inline void maxChunk(std::uint8_t* target, const std::uint8_t* values, const std::uint8_t* mask) {
  std::uint8_t chunk[kChunk], add[kChunk];
  std::memcpy(chunk, target, kChunk);
  std::memcpy(add, values, kChunk);
  for (long i = 0; i < kChunk; ++i)
    chunk[i] = std::max(chunk[i], static_cast<std::uint8_t>(add[i] & mask[i]));
  std::memcpy(target, chunk, kChunk);
}

/// target[i] = max(target[i], values[i]) for i < count, in chunks: the bytes of the last chunk past
/// `count` are maxed with zero, which leaves them as they are (both arrays must be readable and writable
/// that far). A stamp's bytes past its row's end are zeros, or in the next row or tile (left unchanged).
inline void maxInto(std::uint8_t* target, const std::uint8_t* values, long count) {
  for (; count > 0; count -= kChunk, target += kChunk, values += kChunk) {
    maxChunk(target, values, kLeadingBytes.mask[std::min(count, kChunk)]);
  }
}

/// floor() for the table's coordinates (|value| far below 2^62), without a library call.
inline long floorToLong(double value) {
  const long truncated = static_cast<long>(value);
  return value < static_cast<double>(truncated) ? truncated - 1 : truncated;
}

}  // namespace

TableKernel gradedKernel(const LookupTableOptions& options) {
  // The value of a cell is the likelihood of the distance from the reference point's cell centre to its own.
  TableKernel kernel;
  kernel.radius = static_cast<int>(std::ceil(options.cutoff * (1.0 / options.cell_size) - 1e-9));
  const int side = 2 * kernel.radius + 1;
  kernel.values.assign(static_cast<std::size_t>(side) * side, 0);
  const double inv_two_sigma_sq = 1.0 / (2.0 * options.sigma * options.sigma);
  for (int dy = -kernel.radius; dy <= kernel.radius; ++dy) {
    for (int dx = -kernel.radius; dx <= kernel.radius; ++dx) {
      const double distance = std::hypot(dx, dy) * options.cell_size;
      if (distance > options.cutoff) continue;
      kernel.values[(dy + kernel.radius) * side + dx + kernel.radius] =
          static_cast<std::uint8_t>(std::lround(255.0 * std::exp(-distance * distance * inv_two_sigma_sq)));
    }
  }
  return kernel;
}

LookupTableOptions LookupTable::validated(LookupTableOptions options) {
  // Guard against nonsense sizes here too; the ROS layer validates and names the parameter.
  if (!(options.cell_size > 1e-4)) options.cell_size = LookupTableOptions().cell_size;
  if (!(options.sigma > 0.0)) options.sigma = LookupTableOptions().sigma;
  if (!(options.cutoff >= options.cell_size)) options.cutoff = std::max(options.cell_size, 3 * options.sigma);
  return options;
}

LookupTable::LookupTable(const LookupTableOptions& options, TableKernelFunction kernel)
    : options_(validated(options)), inv_cell_size_(1.0 / options_.cell_size) {
  TableKernel stamp = kernel ? kernel(options_) : gradedKernel(options_);
  const auto side = static_cast<std::size_t>(2 * stamp.radius + 1);
  if (stamp.radius < 0 || stamp.values.size() != side * side) stamp = gradedKernel(options_);
  setKernel(stamp);
}

void LookupTable::setKernel(const TableKernel& kernel) {
  // The stamp around one reference point, precomputed once.
  kernel_radius_ = kernel.radius;
  const int side = 2 * kernel_radius_ + 1;
  // Rows padded with zeros (and the last one followed by zeros) for the stamps' 16-byte reads.
  kernel_stride_ = side + kChunk;
  kernel_.assign(static_cast<std::size_t>(kernel_stride_) * side + kChunk, 0);
  for (int row = 0; row < side; ++row) {
    std::copy_n(&kernel.values[static_cast<std::size_t>(row) * side], side, &kernel_[row * kernel_stride_]);
  }
  const auto largest = std::max_element(kernel.values.begin(), kernel.values.end());
  max_cell_value_ = std::max<std::uint32_t>(1, *largest);
  kernel_spans_.assign(static_cast<std::size_t>(side), {0, 0});
  for (int row = 0; row < side; ++row) {
    const std::uint8_t* values = &kernel_[static_cast<std::size_t>(row) * kernel_stride_];
    int first = 0, last = side;
    while (first < side && values[first] == 0) ++first;
    while (last > first && values[last - 1] == 0) --last;
    kernel_spans_[row] = {first, last};
  }
  kernel_rows_ = {0, side};
  while (kernel_rows_.first < side && kernel_spans_[kernel_rows_.first].first == side) ++kernel_rows_.first;
  while (kernel_rows_.second > kernel_rows_.first && kernel_spans_[kernel_rows_.second - 1].first == side) {
    --kernel_rows_.second;
  }
}

std::size_t LookupTable::memoryBytes() const {
  return tile_offset_.capacity() * sizeof(std::int32_t) + tile_cells_.capacity() +
         stamped_.capacity() * sizeof(std::uint64_t) + kernel_.capacity();
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
    const long cx = floorToLong(p.x() * inv_cell_size_);
    const long cy = floorToLong(p.y() * inv_cell_size_);
    // Samples along a surface fall into the same cell in a row: one entry each run.
    if (!cells_.empty() && cells_.back().first == cx && cells_.back().second == cy) continue;
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

LookupTable::Box LookupTable::tileRange(const Box& box) const {
  const long r = kernel_radius_;
  const auto floor_div = [](long a) {
    return a >= 0 ? a >> kTileShift : -((-a + kTileSize - 1) >> kTileShift);
  };
  Box tiles;
  tiles.min_x = floor_div(box.min_x - r), tiles.max_x = floor_div(box.max_x + r);
  tiles.min_y = floor_div(box.min_y - r), tiles.max_y = floor_div(box.max_y + r);
  return tiles;
}

void LookupTable::regrid(const Box& tiles) {
  // The grid sits inside a ring of zero tiles (lookups clamped onto the ring read zero); its rows are a
  // power of two wide. Tiles that have cells keep them: only their entries move.
  const long old_first_x = origin_cell_x_ / kTileSize, old_first_y = origin_cell_y_ / kTileSize;
  const int old_shift = stride_shift_;
  const long old_tiles_x = tiles_x_, old_tiles_y = tiles_y_;
  tiles_x_ = tiles.max_x - tiles.min_x + 1;
  tiles_y_ = tiles.max_y - tiles.min_y + 1;
  origin_cell_x_ = tiles.min_x * kTileSize;
  origin_cell_y_ = tiles.min_y * kTileSize;
  stride_shift_ = 0;
  while ((1L << stride_shift_) < tiles_x_ + 2) ++stride_shift_;
  std::vector<std::int32_t> offsets(static_cast<std::size_t>((tiles_y_ + 2) << stride_shift_), zero_tile_);
  for (long ty = 0; ty < old_tiles_y; ++ty) {
    for (long tx = 0; tx < old_tiles_x; ++tx) {
      const long y = ty + old_first_y - tiles.min_y, x = tx + old_first_x - tiles.min_x;
      offsets[((y + 1) << stride_shift_) + x + 1] = tile_offset_[((ty + 1) << old_shift) + tx + 1];
    }
  }
  tile_offset_.swap(offsets);
}

void LookupTable::allocateTile(long slot) {
  std::int32_t& offset = tile_offset_[slot];
  if (offset != zero_tile_) return;
  offset = static_cast<std::int32_t>(tile_slots_++ * kTileCells);
  ++tiles_in_use_;
}

void LookupTable::allocateTiles(const Box& box) {
  const Box tiles = tileRange(box);
  if (tile_offset_.empty()) {
    // The first tile of cells is the zero tile every tile without cells shares.
    tile_slots_ = 1;
    zero_tile_ = 0;
    tiles_in_use_ = 0;
    tiles_x_ = tiles_y_ = 0;
    regrid(tiles);
  } else {
    const long first_x = origin_cell_x_ / kTileSize, first_y = origin_cell_y_ / kTileSize;
    Box grown = tiles;
    grown.min_x = std::min(grown.min_x, first_x), grown.max_x = std::max(grown.max_x, first_x + tiles_x_ - 1);
    grown.min_y = std::min(grown.min_y, first_y), grown.max_y = std::max(grown.max_y, first_y + tiles_y_ - 1);
    if (grown.min_x < first_x || grown.min_y < first_y || grown.max_x >= first_x + tiles_x_ ||
        grown.max_y >= first_y + tiles_y_) {
      regrid(grown);
    }
  }
  // A stamp spans at most two tiles each way (a tile is wider than a stamp).
  const long r = kernel_radius_;
  for (const auto& cell : cells_) {
    const long x = cell.first - origin_cell_x_, y = cell.second - origin_cell_y_;
    const long x0 = (x - r) >> kTileShift, x1 = (x + r) >> kTileShift;
    const long y0 = (y - r) >> kTileShift, y1 = (y + r) >> kTileShift;
    for (long ty = y0; ty <= y1; ++ty) {
      for (long tx = x0; tx <= x1; ++tx) allocateTile(((ty + 1) << stride_shift_) + tx + 1);
    }
  }
  // A stamp's last 16-byte maximum may reach past the last tile (with zeros: it changes nothing there).
  tile_cells_.resize(tile_slots_ * kTileCells + kChunk, 0);
  stamped_.resize((tile_slots_ * kTileCells + 63) / 64, 0);
}

void LookupTable::clear() {
  tiles_in_use_ = tile_slots_ = 0;
  tiles_x_ = tiles_y_ = 0;
  origin_cell_x_ = origin_cell_y_ = 0;
  tile_offset_.clear();
  tile_cells_.clear();
  stamped_.clear();
}

void LookupTable::build(const ReferencePoints& reference_set) {
  clear();
  insert(reference_set);
}

void LookupTable::insert(const ReferencePoints& reference_set) {
  Box box;
  if (!collectCells(reference_set, &box)) return;
  allocateTiles(box);
  // Stamp the kernel around each point, keeping the maximum (likelihood of the nearest point). A stamp
  // depends on the centre's cell only: overlapping keyframes and close samples put many in one cell, which
  // is stamped once, in any order.
  for (const auto& cell : cells_) {
    const long cx = cell.first - origin_cell_x_, cy = cell.second - origin_cell_y_;
    const std::size_t offset = cellOffset(cx, cy);
    std::uint64_t& word = stamped_[offset / 64];
    const std::uint64_t bit = std::uint64_t{1} << (offset % 64);
    if (word & bit) continue;
    word |= bit;
    stamp(cx, cy);
  }
}

void LookupTable::stamp(long cx, long cy) {
  const long r = kernel_radius_;
  if (2 * r + 1 > kTileSize) {
    stampWide(cx, cy);
    return;
  }
  const long x0 = cx - r, y0 = cy - r;  // the stamp's first column and row
  // A tile is wider than a stamp: its columns cross at most one tile edge, at kernel column `split`, and
  // its rows at most one, at kernel row `split_row`.
  const long tile_x = x0 >> kTileShift, in_tile_x = x0 & (kTileSize - 1);
  const long split = kTileSize - in_tile_x;
  const long split_row = kTileSize - (y0 & (kTileSize - 1));
  const std::int32_t* upper = &tile_offset_[tileSlot(0, y0, stride_shift_)];
  const std::int32_t* lower = &tile_offset_[tileSlot(0, y0 + kTileSize, stride_shift_)];
  // Each side's cell of the stamp's first row (kernel row 0) in the upper tiles and, shifted back by
  // split_row rows, in the lower ones: the cell of kernel row ky is then base + ky * kTileSize.
  std::uint8_t* cells = tile_cells_.data();
  const long first_row = (y0 & (kTileSize - 1)) << kTileShift;
  std::uint8_t* upper_left = cells + upper[tile_x] + first_row + in_tile_x;
  std::uint8_t* upper_right = cells + upper[tile_x + 1] + first_row - split;
  std::uint8_t* lower_left = cells + lower[tile_x] - split_row * kTileSize + in_tile_x;
  std::uint8_t* lower_right = cells + lower[tile_x + 1] - split_row * kTileSize - split;
  // Only the kernel's non-zero rows (a round kernel leaves the square's outer rows empty).
  const long rows_up = std::clamp(split_row, kernel_rows_.first, kernel_rows_.second);
  stampRows(kernel_rows_.first, rows_up, split, upper_left, upper_right);
  stampRows(rows_up, kernel_rows_.second, split, lower_left, lower_right);
}

void LookupTable::stampWide(long cx, long cy) {
  // A kernel wider than a tile (not the presets'): each row in runs that stay within one tile.
  const long r = kernel_radius_;
  for (long ky = kernel_rows_.first; ky < kernel_rows_.second; ++ky) {
    const long ly = cy - r + ky;
    const std::int32_t* offsets = &tile_offset_[tileSlot(0, ly, stride_shift_)];
    const long row = (ly & (kTileSize - 1)) << kTileShift;
    const long end = kernel_spans_[ky].second;
    for (long kx = kernel_spans_[ky].first; kx < end;) {
      const long lx = cx - r + kx;
      const long in_tile = lx & (kTileSize - 1);
      const long run = std::min(end - kx, kTileSize - in_tile);
      maxInto(&tile_cells_[offsets[lx >> kTileShift] + row + in_tile], &kernel_[ky * kernel_stride_ + kx],
              run);
      kx += run;
    }
  }
}

void LookupTable::stampRows(long begin, long end, long split, std::uint8_t* left, std::uint8_t* right) {
  // Locals, not members: the byte stores below may alias anything, so members would be reloaded per row.
  const std::uint8_t* kernel = kernel_.data();
  const long kernel_stride = kernel_stride_;
  const std::pair<long, long>* spans = kernel_spans_.data();
  const bool narrow = 2 * kernel_radius_ + 1 <= kChunk;  // a row in one chunk (the defaults: 15 of 17)
  const std::uint8_t* all = kLeadingBytes.mask[kChunk];
  for (long ky = begin; ky < end; ++ky) {
    std::uint8_t* row_left = left + ky * kTileSize;
    std::uint8_t* row_right = right + ky * kTileSize;
    const std::uint8_t* kernel_row = kernel + ky * kernel_stride;
    const long first = spans[ky].first, last = spans[ky].second;
    if (narrow) {
      // One chunk on each side of the edge: masked before it; past the span the kernel row is zero.
      if (last <= split) {
        maxChunk(row_left + first, kernel_row + first, all);
      } else if (first >= split) {
        maxChunk(row_right + first, kernel_row + first, all);
      } else {
        maxChunk(row_left + first, kernel_row + first, kLeadingBytes.mask[split - first]);
        maxChunk(row_right + split, kernel_row + split, all);
      }
    } else {
      maxInto(row_left + first, kernel_row + first, std::min(last, split) - first);
      const long right_first = std::max(first, split);
      maxInto(row_right + right_first, kernel_row + right_first, last - right_first);
    }
  }
}

std::uint8_t LookupTable::valueAt(const Eigen::Vector2d& query_point) const {
  return valueInTable(query_in_table_ * query_point);
}

std::uint8_t LookupTable::valueInTable(const Eigen::Vector2d& point) const {
  if (tiles_in_use_ == 0) return 0;
  const double fx = point.x() * inv_cell_size_ - origin_cell_x_;
  const double fy = point.y() * inv_cell_size_ - origin_cell_y_;
  if (!(fx >= 0.0 && fy >= 0.0 && fx < tiles_x_ * kTileSize && fy < tiles_y_ * kTileSize)) return 0;
  return tile_cells_[cellOffset(static_cast<long>(fx), static_cast<long>(fy))];
}

int LookupTable::beamsThroughSurfaces(const std::vector<Eigen::Vector2d>& points, const Pose2D& sensor,
                                      double margin) const {
  if (tiles_in_use_ == 0 || !sensor.isFinite()) return 0;
  // Steps of one cell: a graded surface's band (value >= max / 2) is 2.4 sigma wide.
  const double step = 1.0 / inv_cell_size_;
  const auto surface = static_cast<std::uint8_t>(std::max<std::uint32_t>(1, maxCellValue() / 2));
  // In the table's own frame; a beam is walked only where it crosses the table's extent (a wild reading
  // kilometres out would otherwise take millions of steps through nothing).
  const Pose2D in_table = query_in_table_ * sensor;
  const Eigen::Vector2d origin = in_table.translation();
  const Eigen::Vector2d low(origin_cell_x_ * step, origin_cell_y_ * step);
  const Eigen::Vector2d high = low + Eigen::Vector2d(tiles_x_, tiles_y_) * (kTileSize * step);
  int through = 0;
  for (const Eigen::Vector2d& point : points) {
    const double range = point.norm();
    if (!std::isfinite(range) || range <= 2.0 * margin) continue;
    const Eigen::Vector2d direction = (in_table * point - origin) / range;
    double enter = margin, leave = range - margin;
    for (int axis = 0; axis < 2 && enter < leave; ++axis) {
      if (direction[axis] == 0.0) {
        if (origin[axis] < low[axis] || origin[axis] > high[axis]) leave = enter;
        continue;
      }
      const double a = (low[axis] - origin[axis]) / direction[axis];
      const double b = (high[axis] - origin[axis]) / direction[axis];
      enter = std::max(enter, std::min(a, b));
      leave = std::min(leave, std::max(a, b));
    }
    // The same samples as a walk from the margin (every step from it), skipping those before the table.
    const double first = margin + std::max(0.0, std::ceil((enter - margin) / step)) * step;
    for (double r = first; r < leave; r += step) {
      if (valueInTable(origin + r * direction) >= surface) {
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
  x.reserve(points.size());
  y.reserve(points.size());
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
