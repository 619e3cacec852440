// SPDX-License-Identifier: GPL-3.0-or-later
#include "eval/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::eval {

namespace {

// A polygon vertex: x, y in the heading-aligned frame centred on the origin, z in the world.
struct Vertex {
  double x, y, z;
};

// A triangle clipped by at most six planes has at most nine vertices: no allocation.
struct Polygon {
  std::array<Vertex, 12> v;
  int n = 0;
  void push(const Vertex& p) { v[static_cast<size_t>(n++)] = p; }
};

// Sutherland-Hodgman against one half-space {side(p) >= 0}. Exact for planar convex
// polygons, also for degenerate ones (a vertical triangle projects to a segment).
template <class Side>
Polygon clip(const Polygon& in, Side side) {
  Polygon out;
  for (int i = 0; i < in.n; ++i) {
    const Vertex& a = in.v[static_cast<size_t>(i)];
    const Vertex& b = in.v[static_cast<size_t>((i + 1) % in.n)];
    const double sa = side(a);
    const double sb = side(b);
    if (sa >= 0.0) out.push(a);
    if ((sa >= 0.0) != (sb >= 0.0)) {
      const double t = sa / (sa - sb);
      out.push(Vertex{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)});
    }
  }
  return out;
}

Polygon clip_to_slab(const Polygon& in, double lo, double hi) {
  const Polygon above = clip(in, [lo](const Vertex& p) { return p.z - lo; });
  return clip(above, [hi](const Vertex& p) { return hi - p.z; });
}

struct Closest {
  double range = INFINITY;
  Vertex point{NAN, NAN, NAN};
};

// Closest point of a convex polygon (as a union of its edges) to the vertical axis x = y = 0.
Closest closest_on_edges(const Polygon& poly) {
  Closest best;
  for (int i = 0; i < poly.n; ++i) {
    const Vertex& a = poly.v[static_cast<size_t>(i)];
    const Vertex& b = poly.v[static_cast<size_t>((i + 1) % poly.n)];
    const double ex = b.x - a.x;
    const double ey = b.y - a.y;
    const double length2 = ex * ex + ey * ey;
    double t = length2 > 0.0 ? -(a.x * ex + a.y * ey) / length2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const Vertex p{a.x + t * ex, a.y + t * ey, a.z + t * (b.z - a.z)};
    const double range = std::sqrt(p.x * p.x + p.y * p.y);
    if (range < best.range) best = Closest{range, p};
  }
  return best;
}

// A lower bound of the polygon's distance to the axis, exact up to rounding: 0 when the
// polygon surrounds the axis (every edge turns the same way around it and the area is not
// degenerate), else the closest edge. A sliver of area A around the axis that is taken as
// degenerate has its edges within 2A / perimeter of the axis anyway.
double distance_to_axis(const Polygon& poly) {
  double twice_area = 0.0, extent2 = 0.0;
  bool turns_left = true, turns_right = true;
  for (int i = 0; i < poly.n; ++i) {
    const Vertex& a = poly.v[static_cast<size_t>(i)];
    const Vertex& b = poly.v[static_cast<size_t>((i + 1) % poly.n)];
    const double cross = a.x * b.y - a.y * b.x;
    twice_area += cross;
    turns_left = turns_left && cross >= 0.0;
    turns_right = turns_right && cross <= 0.0;
    extent2 = std::max(extent2, a.x * a.x + a.y * a.y);
  }
  if ((turns_left || turns_right) && std::abs(twice_area) > 1e-12 * extent2) return 0.0;
  return closest_on_edges(poly).range;
}

// Unit directions of the wedge edges: edge k at azimuth k * width degrees.
std::vector<Eigen::Vector2d> wedge_edges(int bins) {
  std::vector<Eigen::Vector2d> edges(static_cast<size_t>(bins) + 1);
  for (int k = 0; k <= bins; ++k) {
    const double a = 2.0 * M_PI * k / bins;
    edges[static_cast<size_t>(k)] = Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  return edges;
}

// Closest point of the polygon inside the wedge from direction d0 counter-clockwise to d1
// (less than or equal to 180 degrees apart): the intersection of two half-planes.
Closest closest_in_wedge(const Polygon& poly, const Eigen::Vector2d& d0,
                         const Eigen::Vector2d& d1) {
  const Polygon left_of_d0 =
      clip(poly, [&](const Vertex& p) { return d0.x() * p.y - d0.y() * p.x; });
  const Polygon wedge =
      clip(left_of_d0, [&](const Vertex& p) { return p.x * d1.y() - p.y * d1.x(); });
  return closest_on_edges(wedge);
}

// The bins a polygon can reach: [first, first + count) modulo bins, from its vertices' azimuths.
// A convex polygon away from the axis spans less than 180 degrees, so its vertices bound it.
struct BinSpan {
  int first = 0;
  int count = 0;
};

BinSpan reachable_bins(const Polygon& poly, double distance_to_axis, int bins) {
  const BinSpan all{0, bins};
  if (distance_to_axis < 1e-9) return all;
  const double a0 = std::atan2(poly.v[0].y, poly.v[0].x);
  double lo = 0.0, hi = 0.0;
  for (int i = 1; i < poly.n; ++i) {
    const double delta =
        std::remainder(std::atan2(poly.v[static_cast<size_t>(i)].y,
                                  poly.v[static_cast<size_t>(i)].x) - a0, 2.0 * M_PI);
    lo = std::min(lo, delta);
    hi = std::max(hi, delta);
  }
  if (hi - lo >= M_PI - 1e-9) return all;
  const double bin_width = 2.0 * M_PI / bins;
  // A vertex on a bin edge lies in both closed wedges; the 1e-9 bin margin (far above atan2's
  // rounding) makes sure both are visited.
  const int first = static_cast<int>(std::floor((a0 + lo) / bin_width - 1e-9));
  const int last = static_cast<int>(std::floor((a0 + hi) / bin_width + 1e-9));
  const int count = std::min(last - first + 1, bins);
  return BinSpan{((first % bins) + bins) % bins, count};
}

class CellUpdater {
 public:
  CellUpdater(const RasterOrigin& origin, const RasterConfig& config)
      : origin_(origin), config_(config), edges_(wedge_edges(config.azimuth_bins)),
        cos_(std::cos(origin.heading)), sin_(std::sin(origin.heading)) {}

  // The triangle in the heading-aligned frame.
  Polygon local(const GroundTruthTriangle& tri) const {
    Polygon poly;
    for (const Eigen::Vector3d& p : tri) {
      const double dx = p.x() - origin_.position.x();
      const double dy = p.y() - origin_.position.y();
      poly.push(Vertex{cos_ * dx + sin_ * dy, -sin_ * dx + cos_ * dy, p.z()});
    }
    return poly;
  }

  // Lowers every cell of `cells` (one per bin) in `span` that the slab-clipped polygon reaches.
  void update(const Polygon& slab_polygon, const BinSpan& span, RasterCell* cells) const {
    if (slab_polygon.n == 0) return;
    const double lower_bound = distance_to_axis(slab_polygon);
    if (lower_bound > config_.max_range) return;
    const int bins = config_.azimuth_bins;
    for (int i = 0; i < span.count; ++i) {
      const int bin = (span.first + i) % bins;
      RasterCell& cell = cells[bin];
      if (lower_bound >= cell.range) continue;  // cannot lower this cell
      const Closest c = closest_in_bin(slab_polygon, bin);
      if (c.range <= config_.max_range && c.range < cell.range) {
        cell.range = static_cast<float>(c.range);
        cell.point = world_point(c.point);
      }
    }
  }

 private:
  Closest closest_in_bin(const Polygon& poly, int bin) const {
    const Eigen::Vector2d& d0 = edges_[static_cast<size_t>(bin)];
    const Eigen::Vector2d& d1 = edges_[static_cast<size_t>(bin) + 1];
    if (config_.azimuth_bins >= 2) return closest_in_wedge(poly, d0, d1);
    // A single 360-degree bin: two half-plane wedges of 180 degrees.
    const Eigen::Vector2d back(-1.0, 0.0);
    const Closest upper = closest_in_wedge(poly, d0, back);
    const Closest lower = closest_in_wedge(poly, back, d1);
    return upper.range <= lower.range ? upper : lower;
  }

  Eigen::Vector3f world_point(const Vertex& p) const {
    return Eigen::Vector3d(origin_.position.x() + cos_ * p.x - sin_ * p.y,
                           origin_.position.y() + sin_ * p.x + cos_ * p.y, p.z)
        .cast<float>();
  }

  RasterOrigin origin_;
  RasterConfig config_;
  std::vector<Eigen::Vector2d> edges_;
  double cos_, sin_;
};

}  // namespace

GroundTruthRasters ground_truth_rasters(const std::vector<GroundTruthTriangle>& triangles,
                                        const RasterOrigin& origin, const RasterConfig& config) {
  config.validate();
  if (!origin.position.allFinite() || !std::isfinite(origin.heading) ||
      !std::isfinite(origin.ground_z)) {
    throw std::invalid_argument("ground truth: the raster origin is not finite");
  }
  GroundTruthRasters truth{make_circle(config), make_cylinder(config)};
  const CellUpdater updater(origin, config);
  const double band_lo = origin.ground_z + config.band_min;
  const double band_hi = origin.ground_z + config.band_max;
  const int rows = config.rows();

  for (size_t t = 0; t < triangles.size(); ++t) {
    const GroundTruthTriangle& tri = triangles[t];
    if (!tri[0].allFinite() || !tri[1].allFinite() || !tri[2].allFinite()) {
      throw std::invalid_argument("ground truth: triangle " + std::to_string(t) +
                                  " has a non-finite vertex");
    }
    const double z_lo = std::min({tri[0].z(), tri[1].z(), tri[2].z()});
    const double z_hi = std::max({tri[0].z(), tri[1].z(), tri[2].z()});
    if (z_hi < band_lo || z_lo > band_hi) continue;
    const Polygon poly = updater.local(tri);
    const Polygon band = clip_to_slab(poly, band_lo, band_hi);
    if (band.n == 0) continue;
    // Every row polygon lies inside the band polygon: one range cull and one angular extent
    // serve the circle and all rows.
    const double band_range = distance_to_axis(band);
    if (band_range > config.max_range) continue;
    const BinSpan span = reachable_bins(band, band_range, config.azimuth_bins);

    updater.update(band, span, truth.circle.bins.data());
    for (int row = 0; row < rows; ++row) {
      const double lo = origin.ground_z + config.row_bottom(row);
      const double hi = origin.ground_z + config.row_top(row);
      if (z_hi < lo || z_lo > hi) continue;
      updater.update(clip_to_slab(poly, lo, hi), span, &truth.cylinder.at(row, 0));
    }
  }
  return truth;
}

}  // namespace sonomap::eval
