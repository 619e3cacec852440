// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/rasteriser.hpp"

#include <cmath>
#include <stdexcept>

namespace sonomap {

namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;
constexpr double kAxisRange = 1e-9;      // metres: closer to the vertical axis has no azimuth
constexpr double kEdgeSnapDeg = 1e-9;    // degrees: rounding noise of atan2 at bin edges

// atan2(y, x) in degrees within kFastAtanErrorDeg, without a libm call (Abramowitz and Stegun
// 4.4.47 on [0, 1], |error| <= 1e-5 rad, then the octant). Most points then need no exact
// atan2: only one that lands this close to a bin edge is binned again the exact way, so the
// bins are exactly those of atan2 (a frame's 80 thousand surface samples cost 4 ms of atan2).
constexpr double kFastAtanErrorDeg = 2e-3;  // the polynomial's 5.7e-4 degrees, with room

double fast_atan2_deg(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const double t = steep ? ax / ay : ay / ax;  // in [0, 1]
  const double t2 = t * t;
  double a = t * (0.9998660 + t2 * (-0.3302995 + t2 * (0.1801410 + t2 * (-0.0851330 + t2 * 0.0208351))));
  if (steep) a = M_PI / 2 - a;
  if (x < 0.0) a = M_PI - a;
  if (y < 0.0) a = -a;
  return a * kDegreesPerRadian;
}

}  // namespace

Rasteriser::Rasteriser(const RasterConfig& config) : config_(config) {
  config_.validate();
  max_range2_ = config_.max_range * config_.max_range;
  circle_ = make_circle(config_);
  cylinder_ = make_cylinder(config_);
}

void Rasteriser::reset(const RasterOrigin& origin) {
  if (!origin.position.allFinite() || !std::isfinite(origin.heading) ||
      !std::isfinite(origin.ground_z)) {
    throw std::invalid_argument("Rasteriser::reset: raster origin is not finite");
  }
  origin_ = origin;
  cos_heading_ = std::cos(origin.heading);
  sin_heading_ = std::sin(origin.heading);
  circle_.clear();
  cylinder_.clear();
}

void Rasteriser::add(const Eigen::Vector3f& point) {
  if (!point.allFinite()) return;
  const double height = static_cast<double>(point.z()) - origin_.ground_z;
  if (!(height >= config_.band_min && height <= config_.band_max)) return;

  const double dx = static_cast<double>(point.x()) - origin_.position.x();
  const double dy = static_cast<double>(point.y()) - origin_.position.y();
  const double range2 = dx * dx + dy * dy;
  if (range2 > max_range2_ || range2 < kAxisRange * kAxisRange) return;
  const double range = std::sqrt(range2);

  // Rotate the offset by -heading into the body frame (x ahead, y left).
  const double x = cos_heading_ * dx + sin_heading_ * dy;
  const double y = -sin_heading_ * dx + cos_heading_ * dy;
  const int bin = bin_of(x, y);

  const auto range_f = static_cast<float>(range);
  RasterCell& cell = circle_.bins[static_cast<size_t>(bin)];
  if (range_f < cell.range) cell = RasterCell{range_f, point};

  // floor() of a non-negative quotient (the height is in the band): truncation, no libm call.
  int row = static_cast<int>((height - config_.band_min) / config_.row_height);
  // The top edge of the last row is inside it (the band is closed); rounding of the
  // division must not push it out.
  if (row == cylinder_.rows && height <= config_.row_top(cylinder_.rows - 1) + 1e-9) {
    row = cylinder_.rows - 1;
  }
  if (row >= cylinder_.rows) return;
  RasterCell& cyl_cell = cylinder_.at(row, bin);
  if (range_f < cyl_cell.range) cyl_cell = RasterCell{range_f, point};
}

int Rasteriser::bin_of(double x, double y) const {
  const double width = config_.bin_width_deg();
  double fast = fast_atan2_deg(y, x) / width;
  if (fast < 0.0) fast += config_.azimuth_bins;
  const int below = static_cast<int>(fast);  // floor: fast >= 0
  const double margin = kFastAtanErrorDeg / width, above_edge = fast - below;
  if (above_edge > margin && above_edge < 1.0 - margin) return below;
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

void Rasteriser::add(const Eigen::Vector3f* points, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) add(points[i]);
}

}  // namespace sonomap
