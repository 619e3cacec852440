// SPDX-License-Identifier: GPL-3.0-or-later
// The pixel of a depth image that a point in the camera's optical frame (x right, y down,
// z forward) falls in: what a mapper or an evaluator checks a point against the image with.
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>

#include <cmath>
#include <optional>

namespace sonomap {

struct Pixel {
  int u = 0, v = 0;
};

// Where camera-frame point `c` projects, in pixels (pixel centres at whole numbers); none
// behind the camera.
inline std::optional<Eigen::Vector2d> projection(const PinholeIntrinsics& k, const Eigen::Vector3d& c) {
  if (!(c.z() > 0.0)) return std::nullopt;
  return Eigen::Vector2d(k.fx * c.x() / c.z() + k.cx, k.fy * c.y() / c.z() + k.cy);
}

// std::round(x) (halves away from zero) without libm's call: a mapper asks for the pixels of
// about 80,000 points a frame. Exact: x - trunc(x) has no rounding error.
inline double round_half_away(double x) {
  const double whole = std::trunc(x);
  return std::abs(x - whole) >= 0.5 ? whole + std::copysign(1.0, x) : whole;
}

// The pixel whose centre is nearest the projection of camera-frame point `c`; none behind the
// camera, outside the width x height image, or for a non-finite projection.
inline std::optional<Pixel> pixel_of(const PinholeIntrinsics& k, int width, int height, const Eigen::Vector3d& c) {
  const std::optional<Eigen::Vector2d> p = projection(k, c);
  if (!p) return std::nullopt;
  const double u = round_half_away(p->x()), v = round_half_away(p->y());
  if (!(u >= 0.0 && v >= 0.0 && u < width && v < height)) return std::nullopt;
  return Pixel{static_cast<int>(u), static_cast<int>(v)};
}

}  // namespace sonomap
