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
// square roots are cheaper eight at a time than one by one in the second pass), its bin
// position by a fast arctangent and its row quotient. It is written without branches, over
// plain arrays, so that the compiler vectorises it (core/vector_isa.hpp: a copy per
// instruction set; the top-level CMakeLists.txt gives the options it needs and why), and reads
// the points' (x, y, z) floats where they lie (copying them into the batch first cost as many
// instructions as the pass). The second pass, one point at a time, places the points in their
// cells.
constexpr size_t kBatch = 256;

struct Batch {
  float range[kBatch];                     // the horizontal range a cell records
  double bin_position[kBatch];             // fast atan2 / bin width, in [0, bins]
  double row_position[kBatch];             // (height - band_min) / row height
  int64_t counts[kBatch];                  // in the band and the range (0 if not finite)
  int64_t near_edge[kBatch];               // within the fast arctangent's error of a bin edge
};

// The fast arctangent is Abramowitz and Stegun 4.4.47 on [0, 1], |error| <= 1e-5 rad, then
// the octant, without a libm call. Only a point that lands this close to a bin edge is
// binned again the exact way, so the bins are exactly those of atan2.
constexpr double kFastAtanErrorDeg = 2e-3;  // the polynomial's 5.7e-4 degrees, with room

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
    b.counts[i] = (height >= at.band_min) & (height <= at.band_max) & (range2 <= at.max_range2) &
                  (range2 >= kAxisRange * kAxisRange);
    double x, y;
    to_body(at, dx, dy, x, y);
    const double ax = std::abs(x), ay = std::abs(y);
    const bool steep = ay > ax;
    const double t = (steep ? ax : ay) / (steep ? ay : ax);  // in [0, 1]
    const double t2 = t * t;
    const double a0 = t * (0.9998660 + t2 * (-0.3302995 + t2 * (0.1801410 + t2 * (-0.0851330 + t2 * 0.0208351))));
    const double a1 = steep ? M_PI / 2 - a0 : a0;
    const double a2 = x < 0.0 ? M_PI - a1 : a1;
    const double a3 = y < 0.0 ? -a2 : a2;
    const double signed_position = a3 * at.bins_per_radian, wrapped = signed_position + at.bins;
    const double position = signed_position < 0.0 ? wrapped : signed_position;
    const double above_edge = position - std::floor(position);
    b.range[i] = static_cast<float>(std::sqrt(range2));
    b.bin_position[i] = position;
    b.row_position[i] = (height - at.band_min) / at.row_height;
    b.near_edge[i] = (above_edge <= at.margin_bins) | (above_edge >= 1.0 - at.margin_bins);
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

inline void Rasteriser::place(Cells& cells, const Eigen::Vector3f& point, float range, int bin, int row) {
  RasterCell& cell = cells.circle.bins[static_cast<size_t>(bin)];
  if (range < cell.range) cell = RasterCell{range, point};
  if (row < cells.cylinder.rows) {
    RasterCell& cyl_cell = cells.cylinder.at(row, bin);
    if (range < cyl_cell.range) cyl_cell = RasterCell{range, point};
  }
}

inline int Rasteriser::last_row_fix(int row, const Eigen::Vector3f& point) const {
  // The top edge of the last row is inside it (the band is closed); rounding of the
  // division must not push it out.
  const int rows = cells_.cylinder.rows;
  if (row == rows && static_cast<double>(point.z()) - at_.ground_z <= config_.row_top(rows - 1) + 1e-9) {
    return rows - 1;
  }
  return row;
}

void Rasteriser::add_to(Cells& cells, const Eigen::Vector3f* points, size_t count) const {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "points are packed (x, y, z) floats");
  const auto locate_batch = kernel_for(vector_isa(), &locate_baseline, &locate_avx2, &locate_avx512);
  Batch b;
  for (size_t begin = 0; begin < count; begin += kBatch) {
    const size_t n = std::min(kBatch, count - begin);
    locate_batch(n, reinterpret_cast<const float*>(points + begin), at_, b);
    for (size_t k = 0; k < n; ++k) {
      if (!b.counts[k]) continue;
      const Eigen::Vector3f& point = points[begin + k];
      // Both positions are in range for a point that counts: the conversions are floors.
      const int bin = b.near_edge[k] ? exact_bin(point) : static_cast<int>(b.bin_position[k]);
      place(cells, point, b.range[k], bin, last_row_fix(static_cast<int>(b.row_position[k]), point));
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
  // In every cell a pass in order keeps the first of the nearest points. Each part keeps the
  // first of its own nearest, and merging the parts in order with strict "nearer" picks the
  // first of those: the same point. So the parts change no result and can follow the threads
  // there are: one thread adds in one pass, without clearing and merging parts.
  constexpr size_t kMaxParts = 4, kMinPartPoints = 4096;
  const size_t threads = std::min<size_t>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
      static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency())));
  const size_t parts = std::clamp<size_t>(threads, 1, kMaxParts);
  if (parts == 1 || count < parts * kMinPartPoints) {
    add_to(cells_, points, count);
    return;
  }
  parts_.resize(parts, cells_);
  parallel_for_each_index(parts, [&](size_t part) {
    Cells& cells = parts_[part];
    cells.clear();
    const size_t begin = part * count / parts, end = (part + 1) * count / parts;
    add_to(cells, points + begin, end - begin);
  });
  for (size_t part = 0; part < parts; ++part) cells_.merge(parts_[part]);
}

}  // namespace sonomap
