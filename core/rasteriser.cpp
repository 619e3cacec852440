// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/rasteriser.hpp"

#include "core/parallel.hpp"
#include "core/vector_isa.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

namespace sonomap {

namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;
constexpr double kAxisRange = 1e-9;      // metres: closer to the vertical axis has no azimuth
constexpr double kEdgeSnapDeg = 1e-9;    // degrees: rounding noise of atan2 at bin edges

// The first pass over a batch of points finds, for each, whether it counts, its range (the
// square roots are cheaper eight at a time than one by one in the second pass), its bin by a
// fast arctangent and its row. It is written without branches, over plain arrays, so that the
// compiler vectorises it (core/vector_isa.hpp: a copy per instruction set; the top-level
// CMakeLists.txt gives the options it needs and why), and reads the points' (x, y, z) floats
// where they lie (copying them into the batch first cost as many instructions as the pass).
// The second pass, one point at a time, places the points in their cells.
constexpr size_t kBatch = 256;
constexpr int32_t kNotCounted = -1;  // a bin: outside the band or the range, or not finite
constexpr int32_t kNearEdge = -2;    // a bin: it or the row too near an edge for the fast way
constexpr int32_t kNoCell = -1;      // a cylinder cell: above the last row

struct Batch {
  float range[kBatch];  // the horizontal range a cell records
  int32_t bin[kBatch];  // the circle's cell, kNotCounted or kNearEdge
  // The cylinder's cell (row * bins + bin) or kNoCell, for a bin >= 0. 32 bits suffice:
  // RasterConfig::validate() caps the cylinder at kMaxCylinderCells.
  int32_t cell[kBatch];
};

// The fast arctangent is Abramowitz and Stegun 4.4.47 on [0, 1], |error| <= 1e-5 rad, then
// the octant, without a libm call; its argument is a quotient of floats (relative error below
// 2e-7). Only a point that lands this close to a bin edge is binned again the exact way, so
// the bins are exactly those of atan2.
constexpr double kFastAtanErrorDeg = 2e-3;  // the polynomial's 5.7e-4 degrees, with room
// The row quotient is a product with 1 / row height, within 4e-16 of the divided quotient
// relative to its size. Only a quotient this close to a whole number (relative to 1 + its
// size) may floor differently; its point finds its row the exact way.
constexpr double kRowEdgeMargin = 1e-12;

// The horizontal offset (dx, dy) rotated by -heading into the body frame (x ahead, y left).
inline void to_body(const Rasteriser::Placement& at, double dx, double dy, double& x, double& y) {
  x = at.cos_heading * dx + at.sin_heading * dy;
  y = -at.sin_heading * dx + at.cos_heading * dy;
}

SONOMAP_VECTOR_LOOP void locate(size_t n, const float* xyz, const Rasteriser::Placement& placement, Batch& b) {
  const Rasteriser::Placement at = placement;  // locals: a load inside a select could trap
  for (size_t i = 0; i < n; ++i) {
    const double px = xyz[3 * i], py = xyz[3 * i + 1], pz = xyz[3 * i + 2];
    const double height = pz - at.ground_z;
    const double dx = px - at.x, dy = py - at.y;
    const double range2 = dx * dx + dy * dy;
    // NaN fails every comparison, so non-finite points do not count.
    const bool counts = (height >= at.band_min) & (height <= at.band_max) &
                        (range2 <= at.max_range2) & (range2 >= kAxisRange * kAxisRange);
    double x, y;
    to_body(at, dx, dy, x, y);
    const double ax = std::abs(x), ay = std::abs(y);
    const bool steep = ay > ax;
    // In [0, 1]. Divided as floats: a division of doubles cost as much as the rest of the pass.
    const double t = static_cast<float>(steep ? ax : ay) / static_cast<float>(steep ? ay : ax);
    const double t2 = t * t;
    const double a0 = t * (0.9998660 + t2 * (-0.3302995 + t2 * (0.1801410 + t2 * (-0.0851330 + t2 * 0.0208351))));
    const double a1 = steep ? M_PI / 2 - a0 : a0;
    const double a2 = x < 0.0 ? M_PI - a1 : a1;
    const double a3 = y < 0.0 ? -a2 : a2;
    const double signed_position = a3 * at.bins_per_radian, wrapped = signed_position + at.bins;
    const double position = signed_position < 0.0 ? wrapped : signed_position;
    const double above_edge = position - std::floor(position);
    const bool near_edge = (above_edge <= at.margin_bins) | (above_edge >= 1.0 - at.margin_bins);
    // Both positions are in range for a point that counts (converting another is undefined),
    // and not negative: the conversions are floors. 32-bit results: AVX2 has no vector
    // conversion of doubles to 64-bit integers, and without one the loop is not vectorised.
    const int32_t bin = static_cast<int32_t>(counts ? position : 0.0);
    const double row_quotient = (height - at.band_min) * at.rows_per_metre;
    const double above_row_edge = row_quotient - std::floor(row_quotient);
    const double row_margin = kRowEdgeMargin * (1.0 + row_quotient);
    const bool near_row_edge = (above_row_edge <= row_margin) | (above_row_edge >= 1.0 - row_margin);
    const int32_t row = static_cast<int32_t>(counts ? row_quotient : 0.0);
    // The top edge of the last row is inside it (the band is closed); rounding of the
    // quotient must not push it out.
    const bool top_edge = (row == at.rows) & (height <= at.last_row_top);
    const int32_t fixed_row = row - static_cast<int32_t>(top_edge);
    b.range[i] = static_cast<float>(std::sqrt(range2));
    b.bin[i] = counts ? (near_edge | near_row_edge ? kNearEdge : bin) : kNotCounted;
    b.cell[i] = fixed_row < at.rows ? fixed_row * at.bin_count + bin : kNoCell;
  }
}

void locate_baseline(size_t n, const float* xyz, const Rasteriser::Placement& at, Batch& b) {
  locate(n, xyz, at, b);
}
SONOMAP_AVX2_KERNEL void locate_avx2(size_t n, const float* xyz, const Rasteriser::Placement& at, Batch& b) {
  locate(n, xyz, at, b);
}
SONOMAP_AVX512_KERNEL void locate_avx512(size_t n, const float* xyz, const Rasteriser::Placement& at, Batch& b) {
  locate(n, xyz, at, b);
}

}  // namespace

Rasteriser::Rasteriser(const RasterConfig& config) : config_(config) {
  config_.validate();
  at_.band_min = config_.band_min;
  at_.band_max = config_.band_max;
  at_.max_range2 = config_.max_range * config_.max_range;
  at_.bins = config_.azimuth_bins;
  at_.bins_per_radian = kDegreesPerRadian / config_.bin_width_deg();
  at_.margin_bins = kFastAtanErrorDeg / config_.bin_width_deg();
  at_.row_height = config_.row_height;
  at_.rows_per_metre = 1.0 / config_.row_height;
  at_.rows = config_.rows();
  at_.bin_count = config_.azimuth_bins;
  at_.last_row_top = config_.row_top(at_.rows - 1) + 1e-9;
  cells_ = Cells{make_circle(config_), make_cylinder(config_)};
}

void Rasteriser::reset(const RasterOrigin& origin) {
  if (!origin.position.allFinite() || !std::isfinite(origin.heading) ||
      !std::isfinite(origin.ground_z)) {
    throw std::invalid_argument("Rasteriser::reset: raster origin is not finite");
  }
  origin_ = origin;
  at_.x = origin.position.x();
  at_.y = origin.position.y();
  at_.ground_z = origin.ground_z;
  at_.cos_heading = std::cos(origin.heading);
  at_.sin_heading = std::sin(origin.heading);
  cells_.clear();
}

namespace {

// Keeps the point in the cell if it is nearer.
inline void keep_nearer(RasterCell& cell, const Eigen::Vector3f& point, float range) {
  if (range < cell.range) cell = RasterCell{range, point};
}

}  // namespace

void Rasteriser::add_to(Cells& cells, const Eigen::Vector3f* points, size_t count) const {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "points are packed (x, y, z) floats");
  const auto locate_batch = kernel_for(vector_isa(), &locate_baseline, &locate_avx2, &locate_avx512);
  // The cells' arrays held in locals: stores into the cells could otherwise be taken to change
  // the vectors' pointers, reloaded for every point.
  RasterCell* const circle = cells.circle.bins.data();
  RasterCell* const cylinder = cells.cylinder.cells.data();
  Batch b;
  for (size_t begin = 0; begin < count; begin += kBatch) {
    const size_t n = std::min(kBatch, count - begin);
    locate_batch(n, reinterpret_cast<const float*>(points + begin), at_, b);
    for (size_t k = 0; k < n; ++k) {
      const Eigen::Vector3f& point = points[begin + k];
      const int32_t bin = b.bin[k];
      if (bin >= 0) {
        keep_nearer(circle[bin], point, b.range[k]);
        if (b.cell[k] != kNoCell) keep_nearer(cylinder[b.cell[k]], point, b.range[k]);
      } else if (bin == kNearEdge) {
        const int exact = exact_bin(point), row = exact_row(point);
        keep_nearer(circle[exact], point, b.range[k]);
        if (row < at_.rows) keep_nearer(cylinder[row * at_.bin_count + exact], point, b.range[k]);
      }
    }
  }
}

int Rasteriser::exact_bin(const Eigen::Vector3f& point) const {
  const double dx = static_cast<double>(point.x()) - at_.x;
  const double dy = static_cast<double>(point.y()) - at_.y;
  double x, y;
  to_body(at_, dx, dy, x, y);
  const double width = config_.bin_width_deg();
  double bin_position = std::atan2(y, x) * kDegreesPerRadian / width;
  if (bin_position < 0.0) bin_position += config_.azimuth_bins;
  const double nearest_edge = std::round(bin_position);
  if (std::abs(bin_position - nearest_edge) < kEdgeSnapDeg / width) {
    bin_position = nearest_edge;
  }
  int bin = static_cast<int>(std::floor(bin_position));
  if (bin >= config_.azimuth_bins) bin -= config_.azimuth_bins;  // 360 wraps to 0
  return bin;
}

int Rasteriser::exact_row(const Eigen::Vector3f& point) const {
  const double height = static_cast<double>(point.z()) - at_.ground_z;
  const int row = static_cast<int>((height - at_.band_min) / at_.row_height);
  return row == at_.rows && height <= at_.last_row_top ? at_.rows - 1 : row;
}

void Rasteriser::Cells::clear() {
  circle.clear();
  cylinder.clear();
}

void Rasteriser::Cells::merge(const Cells& part) {
  auto take_nearer = [](std::vector<RasterCell>& to, const std::vector<RasterCell>& from) {
    for (size_t i = 0; i < to.size(); ++i)
      if (from[i].range < to[i].range) to[i] = from[i];
  };
  take_nearer(circle.bins, part.circle.bins);
  take_nearer(cylinder.cells, part.cylinder.cells);
}

void Rasteriser::add(const Eigen::Vector3f* points, std::size_t count) {
  const SampleSpan span{points, count};
  add(&span, 1);
}

void Rasteriser::add_to(Cells& cells, const SampleSpan* spans, size_t span_count, size_t begin,
                        size_t end) const {
  size_t span_begin = 0;  // the index of the span's first point among all the spans' points
  for (size_t i = 0; i < span_count; ++i) {
    const SampleSpan& span = spans[i];
    const size_t from = std::max(begin, span_begin), to = std::min(end, span_begin + span.count);
    if (from < to) add_to(cells, span.points + (from - span_begin), to - from);
    span_begin += span.count;
  }
}

void Rasteriser::add(const SampleSpan* spans, size_t span_count) {
  // In every cell a pass in order keeps the first of the nearest points. Each part keeps the
  // first of its own nearest, and merging the parts in order with strict "nearer" picks the
  // first of those: the same point. So the parts change no result and can follow the threads
  // there are: one thread adds in one pass, without clearing and merging parts.
  constexpr size_t kMaxParts = 4, kMinPartPoints = 4096;
  size_t count = 0;
  for (size_t i = 0; i < span_count; ++i) count += spans[i].count;
  const size_t threads = std::min<size_t>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
      static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency())));
  const size_t parts = std::clamp<size_t>(threads, 1, kMaxParts);
  if (parts == 1 || count < parts * kMinPartPoints) {
    add_to(cells_, spans, span_count, 0, count);
    return;
  }
  parts_.resize(parts, cells_);
  parallel_for_each_index(parts, [&](size_t part) {
    Cells& cells = parts_[part];
    cells.clear();
    add_to(cells, spans, span_count, part * count / parts, (part + 1) * count / parts);
  });
  for (size_t part = 0; part < parts; ++part) cells_.merge(parts_[part]);
}

}  // namespace sonomap
