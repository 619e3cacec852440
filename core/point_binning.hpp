// SPDX-License-Identifier: GPL-3.0-or-later
// A frame's camera points placed in a world voxel grid, a batch at a time: for each point,
// whether it is fused (finite, within [min_range, max_range] of the camera), its world
// position and its voxel. One branch-free pass per batch that the compiler vectorises (a copy
// per instruction set, core/vector_isa.hpp), as the rasteriser's first pass.
#pragma once

#include <Eigen/Geometry>
#include <openvdb/openvdb.h>

#include <cstddef>
#include <cstdint>

namespace sonomap {

class PointBinner {
 public:
  static constexpr size_t kBatch = 256;

  struct Batch {
    float x[kBatch], y[kBatch], z[kBatch];        // world position, as point sums add it
    int32_t vx[kBatch], vy[kBatch], vz[kBatch];   // floor(world position / voxel); 0 if not fused
    int32_t fused[kBatch];                        // 1 if the point is fused, else 0
    openvdb::Coord voxel(size_t i) const { return openvdb::Coord(vx[i], vy[i], vz[i]); }
  };

  // The camera pose and the limits, as plain numbers for the batch pass.
  struct Pose {
    double rotation[9];  // column-major
    double translation[3];
    double inverse_voxel, min2, max2;
  };

  PointBinner(double voxel, double min_range, double max_range, const Eigen::Isometry3d& world_T_camera);

  // Bins points[0, n), n <= kBatch, into `out`. Positions are bounded (10 km), so a fused
  // point's voxel fits an int.
  void bin(const Eigen::Vector3f* points, size_t n, Batch& out) const;

 private:
  Pose pose_;
};

}  // namespace sonomap
