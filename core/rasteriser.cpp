// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/rasteriser.hpp"

#include "core/parallel.hpp"

#include <cmath>
#include <stdexcept>

namespace sonomap {

namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;
constexpr double kAxisRange = 1e-9;      // metres: closer to the vertical axis has no azimuth
constexpr double kEdgeSnapDeg = 1e-9;    // degrees: rounding noise of atan2 at bin edges

// atan2(y, x) within kFastAtanErrorDeg, without a libm call (Abramowitz and Stegun 4.4.47 on
// [0, 1], |error| <= 1e-5 rad, then the octant). Most points then need no exact atan2: only
// one that lands this close to a bin edge is binned again the exact way, so the bins are
// exactly those of atan2 (a frame's 80 thousand surface samples cost 4 ms of atan2).
constexpr double kFastAtanErrorDeg = 2e-3;  // the polynomial's 5.7e-4 degrees, with room

double fast_atan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const double t = steep ? ax / ay : ay / ax;  // in [0, 1]
  const double t2 = t * t;
  double a = t * (0.9998660 + t2 * (-0.3302995 + t2 * (0.1801410 + t2 * (-0.0851330 + t2 * 0.0208351))));
  if (steep) a = M_PI / 2 - a;
  if (x < 0.0) a = M_PI - a;
  if (y < 0.0) a = -a;
  return a;
}

// Whether a sample at squared range `range2` may be nearer than what `cell` holds. The cell
// takes it when float(sqrt(range2)) < cell.range; range2 >= cell.range^2 (exact in double for
// a float) rules that out without the square root, and most samples are not their cell's
// nearest.
bool may_be_nearer(double range2, const RasterCell& cell) {
  const double held = cell.range;
  return range2 < held * held;
}

}  // namespace

Rasteriser::Rasteriser(const RasterConfig& config) : config_(config) {
  config_.validate();
  max_range2_ = config_.max_range * config_.max_range;
  bins_per_radian_ = kDegreesPerRadian / config_.bin_width_deg();
  fast_margin_bins_ = kFastAtanErrorDeg / config_.bin_width_deg();
  cells_ = Cells{make_circle(config_), make_cylinder(config_)};
}

void Rasteriser::reset(const RasterOrigin& origin) {
  if (!origin.position.allFinite() || !std::isfinite(origin.heading) ||
      !std::isfinite(origin.ground_z)) {
    throw std::invalid_argument("Rasteriser::reset: raster origin is not finite");
  }
  origin_ = origin;
  cos_heading_ = std::cos(origin.heading);
  sin_heading_ = std::sin(origin.heading);
  cells_.clear();
}

void Rasteriser::add_to(Cells& cells, const Eigen::Vector3f& point) const {
  if (!point.allFinite()) return;
  const double height = static_cast<double>(point.z()) - origin_.ground_z;
  if (!(height >= config_.band_min && height <= config_.band_max)) return;

  const double dx = static_cast<double>(point.x()) - origin_.position.x();
  const double dy = static_cast<double>(point.y()) - origin_.position.y();
  const double range2 = dx * dx + dy * dy;
  if (range2 > max_range2_ || range2 < kAxisRange * kAxisRange) return;

  // Rotate the offset by -heading into the body frame (x ahead, y left).
  const double x = cos_heading_ * dx + sin_heading_ * dy;
  const double y = -sin_heading_ * dx + cos_heading_ * dy;
  const int bin = bin_of(x, y);
  const int row = row_of(height);
  RasterCell& cell = cells.circle.bins[static_cast<size_t>(bin)];
  RasterCell* cyl_cell = row < cells.cylinder.rows ? &cells.cylinder.at(row, bin) : nullptr;
  // The circle's cell is never farther than a cylinder cell of its bin, so a sample that
  // cannot beat the circle may still beat the cylinder: test both.
  if (!may_be_nearer(range2, cell) && !(cyl_cell && may_be_nearer(range2, *cyl_cell))) return;

  const auto range = static_cast<float>(std::sqrt(range2));
  if (range < cell.range) cell = RasterCell{range, point};
  if (cyl_cell && range < cyl_cell->range) *cyl_cell = RasterCell{range, point};
}

int Rasteriser::row_of(double height) const {
  // floor() of a non-negative quotient (the height is in the band): truncation, no libm call.
  const int row = static_cast<int>((height - config_.band_min) / config_.row_height);
  // The top edge of the last row is inside it (the band is closed); rounding of the
  // division must not push it out.
  const int rows = cells_.cylinder.rows;
  if (row == rows && height <= config_.row_top(rows - 1) + 1e-9) return rows - 1;
  return row;
}

int Rasteriser::bin_of(double x, double y) const {
  double fast = fast_atan2(y, x) * bins_per_radian_;
  if (fast < 0.0) fast += config_.azimuth_bins;
  const int below = static_cast<int>(fast);  // floor: fast >= 0
  const double above_edge = fast - below;
  if (above_edge > fast_margin_bins_ && above_edge < 1.0 - fast_margin_bins_) return below;
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
  // first of those: the same point. The parts depend on the count alone.
  constexpr size_t kParts = 4, kMinPartPoints = 4096;
  if (count < kParts * kMinPartPoints) {
    for (std::size_t i = 0; i < count; ++i) add_to(cells_, points[i]);
    return;
  }
  parts_.resize(kParts, cells_);
  parallel_for_each_index(kParts, [&](size_t part) {
    Cells& cells = parts_[part];
    cells.clear();
    for (size_t i = part * count / kParts; i < (part + 1) * count / kParts; ++i) add_to(cells, points[i]);
  });
  for (const Cells& part : parts_) cells_.merge(part);
}

}  // namespace sonomap
