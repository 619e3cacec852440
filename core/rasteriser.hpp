// SPDX-License-Identifier: GPL-3.0-or-later
// Builds the circle and the cylinder (docs/conventions.md) from world points around a RasterOrigin.
// One accumulator reused frame after frame: reset() clears the cells, add() is O(1) per point
// and allocates only its parallel scratch, once, so a raster from N points costs O(N + cells).
#pragma once

#include "core/raster.hpp"
#include "core/types.hpp"

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace sonomap {

class Rasteriser {
 public:
  // Throws std::invalid_argument if the config is invalid (RasterConfig::validate).
  explicit Rasteriser(const RasterConfig& config = {});

  // Starts a new raster around `origin`: every cell unknown. Throws std::invalid_argument if
  // the origin's position, heading or ground height is not finite.
  void reset(const RasterOrigin& origin);

  // Adds one world point. It counts when its height above the ground, z - ground_z, lies in
  // [band_min, band_max] and its horizontal range |(q - o).xy| is at most max_range.
  // Points that are skipped, by design:
  //  - non-finite coordinates (NaN / inf);
  //  - a point on the sensor's vertical axis (horizontal range below 1e-9 m): it has no
  //    azimuth, and such a point is the listener's own body, not an obstacle around it.
  // Azimuths within 1e-9 degrees of a bin edge are snapped onto the edge, so a point exactly
  // on an edge always belongs to the bin above it (and 359.9999999999 wraps to bin 0).
  // The cylinder row is floor((z - ground_z - band_min) / row_height); the band's top edge
  // belongs to the last row, heights above the last row's top only reach the circle.
  void add(const Eigen::Vector3f& point) { add_to(cells_, &point, 1); }
  // The same as adding the points one by one in order: with more than one thread, split into
  // parts (one per thread, at most 4) rasterised in parallel and merged so that every cell
  // keeps what one pass in order keeps. The result does not depend on the thread count.
  void add(const Eigen::Vector3f* points, std::size_t count);
  void add(const std::vector<Eigen::Vector3f>& points) { add(points.data(), points.size()); }
  // The same as adding the spans' points one by one, span after span.
  void add(const std::vector<SampleSpan>& spans) { add(spans.data(), spans.size()); }
  void add(const SampleSpan* spans, std::size_t span_count);

  const Circle& circle() const { return cells_.circle; }
  const Cylinder& cylinder() const { return cells_.cylinder; }
  const RasterConfig& config() const { return config_; }
  const RasterOrigin& origin() const { return origin_; }

  // What the per-point pass needs of the config and the origin, as plain numbers.
  struct Placement {
    double x = 0.0, y = 0.0, ground_z = 0.0, cos_heading = 1.0, sin_heading = 0.0;
    double band_min = 0.0, band_max = 0.0, max_range2 = 0.0, row_height = 1.0, rows_per_metre = 1.0;
    double bins = 1.0, bins_per_radian = 1.0;
    double margin_bins = 0.0;  // the fast arctangent's error bound, in bins
    int32_t rows = 1, bin_count = 1;
    double last_row_top = 1.0;  // the last row's top with a margin for the division's rounding
  };

 private:
  struct Cells {
    Circle circle;
    Cylinder cylinder;
    void clear();
    // Takes each of `part`'s cells that is nearer (strictly: at equal range the cell keeps
    // its point, which came first).
    void merge(const Cells& part);
  };
  void add_to(Cells& cells, const Eigen::Vector3f* points, std::size_t count) const;
  // Adds the points [begin, end) of the spans taken one after the other.
  void add_to(Cells& cells, const SampleSpan* spans, std::size_t span_count, std::size_t begin,
              std::size_t end) const;
  // The bin of a point as floor(atan2(y, x) / bin width) in the body frame (x ahead, y left),
  // with the edge snapping described at add().
  int exact_bin(const Eigen::Vector3f& point) const;
  // The row as floor((z - ground_z - band_min) / row_height), the band's top edge kept in the
  // last row.
  int exact_row(const Eigen::Vector3f& point) const;

  RasterConfig config_;
  RasterOrigin origin_;
  Placement at_;
  Cells cells_;
  std::vector<Cells> parts_;  // scratch of add(points, count)
};

}  // namespace sonomap
