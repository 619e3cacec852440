// SPDX-License-Identifier: GPL-3.0-or-later
// A ray's walk through grid cells, for VDB-GPDF's free-space carving (vdb_gpdf/votes.cpp).
#pragma once

#include <openvdb/openvdb.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

namespace sonomap {

// The cells of side 2^Log2Dim voxels that the ray eye + t dir, t in [t0, t1], crosses, in order
// (Amanatides and Woo), with openvdb::math::DDA's arithmetic to the bit (its ties included).
// DDA keeps the cell in a Coord that it steps along an axis chosen at run time; reading that
// Coord back right after the 4-byte store stalled store-to-load forwarding, one instruction
// taking 8% of the samples of VDB-GPDF's per-source loop. Here each axis is a variable of its own.
template <int Log2Dim>
class GridWalk {
 public:
  static constexpr int kDim = 1 << Log2Dim;

  GridWalk(const Eigen::Vector3d& eye, const Eigen::Vector3d& dir, double t0, double t1) : t0_(t0), t1_(t1) {
    const Eigen::Vector3d pos = eye + dir * t0;
    int cell[3];
    for (int a = 0; a < 3; ++a) {
      cell[a] = static_cast<int>(std::floor(pos[a])) & ~(kDim - 1);
      if (dir[a] == 0.0) {  // the axis is never stepped
        step_[a] = 0;
        next_[a] = delta_[a] = std::numeric_limits<double>::max();
      } else {
        const double inv = 1.0 / dir[a];
        step_[a] = inv > 0.0 ? kDim : -kDim;
        next_[a] = t0 + ((inv > 0.0 ? cell[a] + kDim : cell[a]) - pos[a]) * inv;
        delta_[a] = step_[a] * inv;
      }
    }
    x_ = cell[0], y_ = cell[1], z_ = cell[2];
  }

  openvdb::Coord cell() const { return openvdb::Coord(x_, y_, z_); }
  double time() const { return t0_; }
  double next() const { return std::min({t1_, next_[0], next_[1], next_[2]}); }

  // To the next cell; false once past t1.
  bool step() {
    // The nearest crossing; on a tie the later axis, as DDA's MinIndex.
    const int a = next_[2] <= std::min(next_[0], next_[1]) ? 2 : next_[1] <= next_[0] ? 1 : 0;
    t0_ = next_[a];
    next_[a] += delta_[a];
    (a == 0 ? x_ : a == 1 ? y_ : z_) += step_[a];
    return t0_ <= t1_;
  }

 private:
  double t0_, t1_;
  int x_ = 0, y_ = 0, z_ = 0;
  int step_[3];
  double next_[3], delta_[3];
};

}  // namespace sonomap
