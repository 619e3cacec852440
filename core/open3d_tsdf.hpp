// SPDX-License-Identifier: GPL-3.0-or-later
// The reference people know as a mapper: Open3D's ScalableTSDFVolume (16^3 voxel blocks in a
// hash map, projective integration of the depth image, no colour), with the voxel size and
// truncation of our TSDF peer, so every A/B run can include it. Its surface comes from Open3D's
// own marching cubes (Open3D's ray casting is not used: on Debian 12 it returns no hits).
#pragma once

#include "core/mapper.hpp"

#include <memory>

namespace sonomap {

struct Open3dTsdfConfig {
  double voxel = 0.05;       // m
  double truncation = 0.15;  // m (3 voxels, as TsdfConfig)
  double min_range = 0.1;    // m along the ray, as the other mappers
  double max_range = 5.0;
  void validate() const;  // std::invalid_argument on a value out of range
};

class Open3dTsdf final : public Mapper {
 public:
  explicit Open3dTsdf(Open3dTsdfConfig config = {});
  ~Open3dTsdf() override;
  std::string name() const override { return "open3d"; }
  // Integrates frame.depth with frame.intrinsics (a projective integrator needs the image, not
  // the points); pixels whose ray range lies outside [min_range, max_range] are left out.
  // Throws std::invalid_argument for a bad pose, missing intrinsics or a depth image whose size
  // is not width x height, with the map untouched.
  void integrate(const Frame& frame) override;
  // Samples of Open3D's mesh, at most half a voxel apart (the mesh is re-extracted only after
  // an integrate). Not thread-safe against concurrent calls on the same map.
  void surface_points(const Eigen::Vector3d& center, double radius,
                      std::vector<Eigen::Vector3f>& out) const override;
  void surface_points_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                              double z_max, std::vector<Eigen::Vector3f>& out) const override;
  // |TSDF| by trilinear interpolation of Open3D's voxels (at most the truncation), gradient from
  // its derivative; observed only where all 8 neighbouring voxels were.
  void query(const std::vector<Eigen::Vector3f>& points,
             std::vector<DistanceQuery>& out) const override;
  StageTimes last_stage_times() const override { return times_; }
  void surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                    std::vector<Eigen::Vector3i>& triangles) const override;
  // Open3D's voxel storage of the allocated blocks plus the cached mesh.
  size_t memory_bytes() const override;

  const Open3dTsdfConfig& config() const { return config_; }

 private:
  struct Volume;  // Open3D stays out of this header (linked privately to sonomap_core)
  Open3dTsdfConfig config_;
  std::unique_ptr<Volume> volume_;
  StageTimes times_;
};

}  // namespace sonomap
