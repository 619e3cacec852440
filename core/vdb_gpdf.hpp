// SPDX-License-Identifier: GPL-3.0-or-later
// VDB-GPDF (Wu et al. 2024, "VDB-GPDF: Online Gaussian Process Distance Field with VDB
// Structure"), with its fixes:
// per frame, local GPs on a fine temporary VDB, signed distances at query points near the
// surface and along free-space rays, weighted fusion into a global (distance, weight) VDB,
// and a global GP per leaf trained on the marching-cubes zero crossings (G-GPDF).
#pragma once

#include "core/fused_grid.hpp"
#include "core/gp.hpp"
#include "core/mapper.hpp"
#include "core/marching_cubes.hpp"

#include <limits>
#include <memory>
#include <unordered_map>

namespace sonomap {

// Defaults: the reference implementation's RGB-D ("cow") configuration.
struct VdbGpdfConfig {
  double local_voxel = 0.02;   // m, temporary per-frame grid
  int voxel_downsample = 5;    // keep every n-th active local voxel as a GP training point
  double global_voxel = 0.05;  // m
  GpKernel kernel = GpKernel::RevertingSE;
  double lambda = 900.0;       // 1 / lengthscale^2
  double map_noise = 0.01;
  double query_step = 0.05;    // m between query points along the normal
  int trunc_behind = 2;        // query points j = 1..trunc_behind behind the surface
  int trunc_front = 3;         // and j = 1..trunc_front in front of it
  bool free_space_carving = true;
  double carving_step = 0.05;  // m between carving points along the ray
  double variance_cap = 0.1;
  double variance_on_surface = 0.001;
  bool inverse_variance_fusion = false;  // default: every query point has weight 1
  // Fused weight ceiling (0 = none, as in the reference). With a cap c the old value keeps at
  // most c / (c + 1) of its say per frame, so a moved object is carved in bounded time:
  // see carving_frame_bound().
  double weight_cap = 30.0;
  int g_gpdf_min_touched = 10;  // voxels touched in a frame before a leaf's global GP is rebuilt
  double global_map_noise = 0.01;  // noise of the global GPs (on marching-cubes crossings)
  double smooth_min = 100.0;    // s in the smooth minimum over the nearest global GPs
  int global_neighbours = 3;    // global GPs combined per query
  double query_radius = 2.0;    // m: a point farther from every global GP leaf is "unobserved"
  // Query gradients: lengthscale of the soft nearest crossing, in GP lengthscales.
  double gradient_scale = 1.5;
  double recon_min_weight = 0.1;
  double min_range = 0.1;       // m, sensor range filter (distance from the camera)
  double max_range = 5.0;
  // Throws std::invalid_argument naming the first value out of range.
  void validate() const;
  GpParams gp_params() const;         // local GPs
  GpParams global_gp_params() const;  // global GPs
};

// Worst-case number of frames after which a voxel that held distance d_old (>= 0, behind a
// surface) reads negative when every frame brings it carving updates of distance <= -carve
// (carve > 0) with at least one unit of weight: the smallest k with
// d_old r^k - carve (1 - r^k) < 0, r = cap / (cap + 1). Infinite without a cap.
double carving_frame_bound(double weight_cap, double d_old, double carve);

class VdbGpdf final : public FusedGridMapper {
 public:
  explicit VdbGpdf(VdbGpdfConfig config = {});
  ~VdbGpdf() override;
  std::string name() const override { return "vdb_gpdf"; }
  void integrate(const Frame& frame) override;
  // Unsigned distance from the global field (smooth minimum over the nearest global GPs).
  void query(const std::vector<Eigen::Vector3f>& points,
             std::vector<DistanceQuery>& out) const override;
  StageTimes last_stage_times() const override { return times_; }
  size_t memory_bytes() const override;

  const VdbGpdfConfig& config() const { return config_; }
  size_t global_gp_count() const { return global_.size(); }
  DistanceQuery query_point(const Eigen::Vector3f& x) const;

 private:
  struct GlobalLeaf;
  // Re-marches the leaves touched by this frame's fusion (`frame_sums` holds its updates):
  // refreshes their surface samples and, for leaves with enough touched voxels, their
  // global GP training points (or drops the GP when the leaf has no zero crossing).
  void update_global_field(const DistanceWeightGrid& frame_sums);
  Eigen::Vector3d soft_nearest_direction(const Eigen::Vector3d& x,
                                         const std::vector<const GlobalLeaf*>& leaves) const;

  VdbGpdfConfig config_;
  std::unordered_map<openvdb::Coord, std::unique_ptr<GlobalLeaf>, CoordHash> global_;
  StageTimes times_;
  // Per global voxel the time (Frame::time, s) a frame last put it on the free side; never:
  // the lowest float. The arrival rule tells fresh free space from stale by it (updates.cpp).
  openvdb::FloatGrid seen_free_at_{std::numeric_limits<float>::lowest()};
};

}  // namespace sonomap
