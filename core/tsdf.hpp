// SPDX-License-Identifier: GPL-3.0-or-later
// The A/B peer of VDB-GPDF: a projective TSDF on OpenVDB, fused with the one rule both maps use
// (FusedGrid::weighted_average, weight capped) and surfaced by the shared marching cubes.
//
// A frame with a depth image and intrinsics is integrated projectively, as KinectFusion and
// Open3D do: the voxel blocks (8^3 leaves) within the truncation band of the frame's points
// are allocated, and with space carving also the blocks already in the map that lie in the
// camera's frustum, so a moved object's old surface is carved away. Every voxel of those blocks
// projects its centre into the nearest pixel; its signed distance is the distance along that
// pixel's ray from the measured surface to the voxel centre (positive behind the surface), as
// in the ray-traced path and in Open3D, so the band and the range limits mean the same in all
// three. Beyond the truncation behind the surface a voxel is left alone; in front it is
// truncated (with carving) or left alone (without). Each voxel gets at most one update of
// weight 1 per frame. Blocks are fused in parallel, each by one task writing only its own
// voxels, so the map does not depend on the thread count.
//
// A frame without a depth image (an unorganised cloud) falls back to ray tracing its points:
// a DDA through the voxels from the truncation in front of each point (or from the sensor, with
// space carving) to the truncation behind it, one update per ray and voxel.
#pragma once

#include "core/fused_grid.hpp"
#include "core/mapper.hpp"

namespace sonomap {

struct TsdfConfig {
  double voxel = 0.05;       // m
  double truncation = 0.15;  // m (3 voxels)
  // Carve the observed free space in view (on) or fuse only the band around the surface
  // (VDBFusion's default). On, like VDB-GPDF's free-space carving, so A/B runs compare like
  // with like.
  bool space_carving = true;
  double weight_cap = 30.0;    // per-update weight ceiling (0 = none)
  double min_weight = 0.1;     // for queries and the surface
  double min_range = 0.1;
  double max_range = 5.0;
  void validate() const;  // std::invalid_argument on a value out of range
};

class Tsdf final : public FusedGridMapper {
 public:
  explicit Tsdf(TsdfConfig config = {});
  std::string name() const override { return "tsdf"; }
  void integrate(const Frame& frame) override;
  // |TSDF| by trilinear interpolation (at most the truncation), gradient from its derivative;
  // observed only where all 8 neighbouring voxels were.
  void query(const std::vector<Eigen::Vector3f>& points,
             std::vector<DistanceQuery>& out) const override;
  StageTimes last_stage_times() const override { return times_; }

  const TsdfConfig& config() const { return config_; }
  DistanceQuery query_point(const Eigen::Vector3f& x) const;

 private:
  // Both return the voxels they changed.
  std::vector<LeafChanges> integrate_image(const Frame& frame);
  std::vector<LeafChanges> integrate_rays(const Frame& frame);

  TsdfConfig config_;
  StageTimes times_;
  // Per-frame scratch, kept to spare the allocations: the range-limited depth image, and the
  // leaves a frame updates (one voxel per leaf, at leaf origin / 8; all off between frames).
  std::vector<float> depth_buffer_;
  openvdb::MaskTree blocks_;
};

}  // namespace sonomap
