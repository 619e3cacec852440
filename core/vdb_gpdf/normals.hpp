// SPDX-License-Identifier: GPL-3.0-or-later
// The surface normal at a source point (PCA over the local voxels' centroids around it; in a
// point cloud, over the next rings too). Internal to core/vdb_gpdf*.
#pragma once

#include "core/vdb_gpdf/local_frame.hpp"

#include <Eigen/Core>

#include <vector>

namespace sonomap::gpdf {

// A normal within this of right angles to the line of sight is not trusted: the view leaves the
// surface's side in doubt (LeafQueries::add), or the points are one ring's (of_one_ring).
constexpr double kMinNormalDotRay = 0.1;  // sin 5.7 degrees
constexpr int kNormalReach = 2;  // local voxels around p that the PCA normal sees

// The scatter of points about p, as scalar sums: Eigen's outer product builds a 3x3 temporary
// whose partly overlapping stores and loads stalled store-to-load forwarding (13% of the
// normal's samples on one instruction).
struct Scatter {
  double sx = 0.0, sy = 0.0, sz = 0.0, xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;
  int count = 0;
  void add(const Eigen::Vector3d& d) {  // d relative to p: well conditioned
    sx += d.x(), sy += d.y(), sz += d.z();
    xx += d.x() * d.x(), xy += d.x() * d.y(), xz += d.x() * d.z();
    yy += d.y() * d.y(), yz += d.y() * d.z(), zz += d.z() * d.z();
    ++count;
  }
};

// A plane through the scatter: its normal facing u (zero when the points are too few for a
// plane), and whether they lie along a line, for which any plane through it fits as well, and
// the direction of their widest spread (the line's, if they lie along one).
struct PlaneFit {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  bool line = false;
  Eigen::Vector3d along = Eigen::Vector3d::Zero();
};

// The local voxels' centroids of a local leaf and its neighbours within `reach` of p: where a
// lidar's ring crosses a surface, the ball around p holds that ring only, and the next ring
// (2 degrees on: 7 cm at 2 m) shows which plane through the ring is the surface.
struct WideNeighbourhood {
  const std::vector<LeafCells>& cells;
  const LocalGps& leaves;  // their neighbours
  size_t leaf;
  Scatter around(const Eigen::Vector3d& p, double reach) const {
    Scatter s;
    auto add_leaf = [&](size_t i) {
      // A ring's leaf holds a line of cells: their box, not the leaf's, rules most leaves out.
      if (cells[i].box.squaredExteriorDistance(p) > reach * reach) return;  // out of reach
      for (const auto& cell : cells[i].cells)
        if ((cell.centroid - p).squaredNorm() <= reach * reach) s.add(cell.centroid - p);
    };
    add_leaf(leaf);
    for (int j : leaves.neighbours[leaf]) add_leaf(static_cast<size_t>(j));
    return s;
  }
};

// The surface normal at p (in local voxel c) facing the sensor (u: unit vector from p toward
// it), from the centroids of the frame's local voxels around c (see normals.cpp).
PlaneFit surface_normal(const std::vector<LeafCells>& cells, const LocalGps::IndexAccessor& index,
                        const openvdb::Coord& c, const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                        const WideNeighbourhood* wide, double wide_reach);

}  // namespace sonomap::gpdf
