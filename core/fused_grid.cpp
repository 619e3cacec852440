// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/fused_grid.hpp"

#include "core/parallel.hpp"

#include <cmath>

namespace sonomap {

FusedGrid::FusedGrid(double voxel, float min_weight, double weight_cap)
    : voxel_(voxel),
      min_weight_(min_weight),
      capped_(weight_cap > 0.0),
      weight_cap_(static_cast<float>(weight_cap)),
      cache_(kLeafDim * voxel) {
  openvdb::initialize();
  grid_ = DistanceWeightGrid::create(openvdb::Vec2s(kUnobservedDistance, 0.0f));
}

std::vector<SurfaceMesh> FusedGrid::refresh(const std::vector<openvdb::Coord>& leaves) {
  std::vector<SurfaceMesh> meshes(leaves.size());
  std::vector<std::vector<Eigen::Vector3f>> samples(leaves.size());
  parallel_for_each_index(leaves.size(), [&](size_t i) {
    march_leaf(*grid_, leaves[i], voxel_, min_weight_, meshes[i]);
    sample_surface(meshes[i], 0.5 * voxel_, samples[i]);
  });
  for (size_t i = 0; i < leaves.size(); ++i) cache_.set(leaves[i], std::move(samples[i]));
  return meshes;
}

void FusedGrid::surface_points(const Eigen::Vector3d& center, double radius,
                               std::vector<Eigen::Vector3f>& out) const {
  surface_points_in_band(center, radius, -INFINITY, INFINITY, out);
}

void FusedGrid::surface_points_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                                       double z_max, std::vector<Eigen::Vector3f>& out) const {
  out.clear();
  cache_.collect(center, radius, z_min, z_max, out);
}

void FusedGrid::surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                             std::vector<Eigen::Vector3i>& triangles) const {
  SurfaceMesh mesh = march_grid(*grid_, voxel_, min_weight_);
  vertices = std::move(mesh.vertices);
  triangles = std::move(mesh.triangles);
}

size_t FusedGrid::memory_bytes() const {
  return static_cast<size_t>(grid_->memUsage()) + cache_.sample_count() * sizeof(Eigen::Vector3f);
}

}  // namespace sonomap
