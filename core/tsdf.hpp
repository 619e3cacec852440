// SPDX-License-Identifier: GPL-3.0-or-later
// The A/B peer of VDB-GPDF: a projective TSDF on OpenVDB in the style of VDBFusion. Each point
// is traced with a DDA through the voxels from truncation in front of it (or from the sensor,
// with space carving) to truncation behind it, and every voxel gets the truncated signed
// distance along the ray in a running weighted average.
#pragma once

#include "core/fused_grid.hpp"
#include "core/mapper.hpp"

namespace sonomap {

struct TsdfConfig {
  double voxel = 0.05;       // m
  double truncation = 0.15;  // m (3 voxels)
  // Trace from the sensor (on) or from truncation in front of the point (VDBFusion's default).
  // On, like VDB-GPDF's free-space carving, so A/B runs compare like with like.
  bool space_carving = true;
  double weight_cap = 30.0;    // per-update weight ceiling (0 = none)
  double min_weight = 0.1;     // for queries and the surface
  double min_range = 0.1;
  double max_range = 5.0;
  void validate() const;  // std::invalid_argument on a value out of range
};

class Tsdf final : public Mapper {
 public:
  explicit Tsdf(TsdfConfig config = {});
  std::string name() const override { return "tsdf"; }
  void integrate(const Frame& frame) override;
  void surface_points(const Eigen::Vector3d& center, double radius,
                      std::vector<Eigen::Vector3f>& out) const override;
  // |TSDF| by trilinear interpolation (at most the truncation), gradient from its derivative;
  // observed only where all 8 neighbouring voxels were.
  void query(const std::vector<Eigen::Vector3f>& points,
             std::vector<DistanceQuery>& out) const override;
  StageTimes last_stage_times() const override { return times_; }
  void surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                    std::vector<Eigen::Vector3i>& triangles) const override;
  size_t memory_bytes() const override;

  const TsdfConfig& config() const { return config_; }
  const DistanceWeightGrid& grid() const { return fused_.grid(); }
  DistanceQuery query_point(const Eigen::Vector3f& x) const;

 private:
  TsdfConfig config_;
  FusedGrid fused_;
  StageTimes times_;
};

}  // namespace sonomap
