// SPDX-License-Identifier: GPL-3.0-or-later
#include "eval/cloud_truth.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::eval {
namespace {

void lower(RasterCell& cell, float range, const Eigen::Vector3f& point) {
  if (range < cell.range) {
    cell.range = range;
    cell.point = point;
  }
}

}  // namespace

GroundTruthRasters cloud_truth_rasters(const std::vector<Eigen::Vector3f>& points,
                                       const RasterOrigin& origin, const RasterConfig& config) {
  config.validate();
  if (!origin.position.allFinite() || !std::isfinite(origin.heading) || !std::isfinite(origin.ground_z))
    throw std::invalid_argument("cloud truth: the raster origin is not finite");
  GroundTruthRasters truth{make_circle(config), make_cylinder(config)};
  const int bins = config.azimuth_bins;
  const double bin_width = 2.0 * M_PI / bins;
  const double band_lo = origin.ground_z + config.band_min;
  const double band_hi = origin.ground_z + config.band_max;
  const int rows = config.rows();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) throw std::invalid_argument("cloud truth: point " + std::to_string(i) + " is not finite");
    if (p.z() < band_lo || p.z() > band_hi) continue;
    const double dx = p.x() - origin.position.x();
    const double dy = p.y() - origin.position.y();
    const double range = std::hypot(dx, dy);
    if (range > config.max_range) continue;
    double azimuth = std::atan2(dy, dx) - origin.heading;
    azimuth -= 2.0 * M_PI * std::floor(azimuth / (2.0 * M_PI));
    const int bin = std::min(bins - 1, static_cast<int>(azimuth / bin_width));
    lower(truth.circle.bins[static_cast<std::size_t>(bin)], static_cast<float>(range), p);
    // Closed rows: a point exactly on a row edge counts in both rows.
    const double height = p.z() - origin.ground_z;
    const int first = std::max(0, static_cast<int>(std::ceil((height - config.band_min) / config.row_height)) - 1);
    for (int row = first; row < rows && config.row_bottom(row) <= height; ++row)
      if (height <= config.row_top(row)) lower(truth.cylinder.at(row, bin), static_cast<float>(range), p);
  }
  return truth;
}

std::vector<Eigen::Vector3f> surface_samples(const std::vector<GroundTruthTriangle>& triangles, double spacing) {
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    throw std::invalid_argument("surface samples: spacing must be positive");
  const double step = 0.8 * spacing;
  std::vector<Eigen::Vector3f> out;
  for (const GroundTruthTriangle& t : triangles) {
    for (int e = 0; e < 3; ++e) {  // the edges, ends included
      const Eigen::Vector3d& a = t[static_cast<std::size_t>(e)];
      const Eigen::Vector3d& b = t[static_cast<std::size_t>((e + 1) % 3)];
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
      for (int i = 0; i < n; ++i) out.push_back((a + (b - a) * (double(i) / n)).cast<float>());
    }
    // The grid in the plane: u along edge 0, v across it; a point (u, v) is inside when it is
    // on the inner side of the other two edges.
    const Eigen::Vector3d e0 = t[1] - t[0];
    const Eigen::Vector3d normal = e0.cross(t[2] - t[0]);
    if (normal.norm() <= 0.0) continue;  // degenerate: its edges are all of it
    const Eigen::Vector3d u = e0.normalized(), v = normal.normalized().cross(u);
    const Eigen::Vector2d p1(e0.norm(), 0.0), p2(u.dot(t[2] - t[0]), v.dot(t[2] - t[0]));
    const auto left_of = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
      return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x()) > 0.0;
    };
    const double u_lo = std::min(0.0, p2.x()), u_hi = std::max(p1.x(), p2.x());
    for (double pv = step; pv < p2.y(); pv += step)  // a lattice: points k step, m step
      for (double pu = step * std::floor(u_lo / step); pu < u_hi; pu += step) {
        const Eigen::Vector2d q(pu, pv);
        if (left_of(p1, p2, q) && left_of(p2, Eigen::Vector2d::Zero(), q))
          out.push_back((t[0] + pu * u + pv * v).cast<float>());
      }
  }
  return out;
}

}  // namespace sonomap::eval
