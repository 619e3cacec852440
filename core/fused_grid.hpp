// SPDX-License-Identifier: GPL-3.0-or-later
// The grid both volumetric maps fuse into, (signed distance, weight) per voxel, with its
// surface: marching cubes over the voxels observed with at least `min_weight`, kept as
// per-leaf samples for the rasters (refreshed only where a frame touched) and as a mesh.
#pragma once

#include "core/mapper.hpp"
#include "core/marching_cubes.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <vector>

namespace sonomap {

class FusedGrid {
 public:
  static constexpr float kUnobservedDistance = -100.0f;  // background: never observed

  // weight_cap: fused weight ceiling (0 = none).
  FusedGrid(double voxel, float min_weight, double weight_cap);
  double voxel() const { return voxel_; }
  DistanceWeightGrid& grid() { return *grid_; }
  const DistanceWeightGrid& grid() const { return *grid_; }

  // The one fusion rule of both maps, a weighted running average: a voxel holding (d, w) that
  // receives updates summing to (sum of w_i d_i, sum of w_i) becomes
  // ((d w + sum w_i d_i) / (w + sum w_i), min(w + sum w_i, cap)). Pass old weight 0 to
  // forget the old value.
  openvdb::Vec2s weighted_average(const openvdb::Vec2s& old, const openvdb::Vec2s& sum) const {
    const float w_new = old[1] + sum[1];
    const float d_new = (old[0] * old[1] + sum[0]) / w_new;
    return openvdb::Vec2s(d_new, capped_ ? std::min<float>(w_new, weight_cap_) : w_new);
  }

  // Re-marches the given leaves (in parallel) and replaces their surface samples; returns
  // each leaf's mesh (empty where the leaf holds no surface).
  std::vector<SurfaceMesh> refresh(const std::vector<openvdb::Coord>& leaves);
  // Replaces `out` with the surface samples within horizontal distance `radius` of center, at
  // most half a voxel apart (the Mapper contract of both maps that fuse into this grid).
  void surface_points(const Eigen::Vector3d& center, double radius,
                      std::vector<Eigen::Vector3f>& out) const;
  // The same restricted to heights z in [z_min, z_max]: leaves outside them are not read.
  void surface_points_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                              double z_max, std::vector<Eigen::Vector3f>& out) const;
  // The same leaves' samples in place, a span per leaf (Mapper::surface_spans_in_band).
  void surface_spans_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                             double z_max, std::vector<SampleSpan>& spans) const {
    cache_.spans(center, radius, z_min, z_max, spans);
  }
  void surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                    std::vector<Eigen::Vector3i>& triangles) const;
  size_t memory_bytes() const;

 private:
  double voxel_;
  float min_weight_;
  bool capped_;
  float weight_cap_;
  DistanceWeightGrid::Ptr grid_;
  SurfaceCache cache_;
};

// A map that fuses into a FusedGrid (the TSDF peer, VDB-GPDF): its surface samples and mesh
// are the grid's.
class FusedGridMapper : public Mapper {
 public:
  void surface_points(const Eigen::Vector3d& center, double radius,
                      std::vector<Eigen::Vector3f>& out) const override {
    fused_.surface_points(center, radius, out);
  }
  void surface_points_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                              double z_max, std::vector<Eigen::Vector3f>& out) const override {
    fused_.surface_points_in_band(center, radius, z_min, z_max, out);
  }
  void surface_spans_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                             double z_max, std::vector<SampleSpan>& spans,
                             std::vector<Eigen::Vector3f>& /*scratch*/) const override {
    fused_.surface_spans_in_band(center, radius, z_min, z_max, spans);
  }
  void surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                    std::vector<Eigen::Vector3i>& triangles) const override {
    fused_.surface_mesh(vertices, triangles);
  }
  // The fused grid's bytes; a map that holds more adds its own.
  size_t memory_bytes() const override { return fused_.memory_bytes(); }
  // The fused grid: x = signed distance (background kUnobservedDistance), y = weight (0).
  const DistanceWeightGrid& grid() const { return fused_.grid(); }

 protected:
  FusedGridMapper(double voxel, float min_weight, double weight_cap)
      : fused_(voxel, min_weight, weight_cap) {}

  FusedGrid fused_;
};

}  // namespace sonomap
