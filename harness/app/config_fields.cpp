// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/config_fields.hpp"

#include "harness/app/run_settings.hpp"

namespace sonomap::harness {

FieldTable vdb_gpdf_fields(VdbGpdfConfig& c) {
  Field voxel = number("global_voxel", &c.global_voxel, "m", kMinVoxel, kMaxVoxel,
                       "global map voxel size (`--voxel`)");
  voxel.aliases = {"voxel"};
  Field carving = flag("free_space_carving", &c.free_space_carving,
                       "carve free space along the rays (removes what has moved away)");
  carving.aliases = {"carving"};
  Choice kernel{{"reverting_se", "log_gpis_matern32"},
                [&c] { return c.kernel == GpKernel::RevertingSE ? 0 : 1; },
                [&c](int i) { c.kernel = i == 0 ? GpKernel::RevertingSE : GpKernel::LogGpisMatern32; }};
  return {
      number("local_voxel", &c.local_voxel, "m", kMinVoxel, 1.0, "per-frame temporary grid voxel size (`--voxel` keeps it at 0.4 voxels)"),
      whole("voxel_downsample", &c.voxel_downsample, 1, 1000,
            "keep every n-th active local voxel as a GP training point (in frames without a "
            "depth image, a local leaf with fewer than 32 active voxels keeps every one: "
            "docs/fidelity.md, \"A lidar's rings\")"),
      voxel,
      {"kernel", kernel, "", {}, "GP kernel of the local and global GPs"},
      positive("lambda", &c.lambda, "1/m^2", 1e8, "kernel parameter: 1 / lengthscale^2 (`--voxel` keeps the lengthscale at 2/3 voxel)"),
      positive("map_noise", &c.map_noise, "", 1e3, "noise of the local GPs"),
      positive("query_step", &c.query_step, "m", kMaxVoxel, "query point spacing along the normal and the ray"),
      whole("trunc_behind", &c.trunc_behind, 0, 100, "query points behind the surface"),
      whole("trunc_front", &c.trunc_front, 0, 100, "query points in front of the surface"),
      carving,
      positive("carving_step", &c.carving_step, "m", kMaxVoxel, "where carving starts in front of a point (`--voxel` keeps it at 1 voxel)"),
      positive("variance_cap", &c.variance_cap, "", 1e6, "GP variance above which a query is dropped"),
      positive("variance_on_surface", &c.variance_on_surface, "", 1e6,
               "variance given to points on the surface"),
      flag("inverse_variance_fusion", &c.inverse_variance_fusion,
           "weight query points by 1 / variance (default: weight 1)"),
      number("weight_cap", &c.weight_cap, "", 0.0, 1e9, "fused weight ceiling (0: none)"),
      whole("g_gpdf_min_touched", &c.g_gpdf_min_touched, 1, 1000000,
            "voxels touched in a frame before a leaf's global GP is rebuilt"),
      positive("global_map_noise", &c.global_map_noise, "", 1e3, "noise of the global GPs"),
      positive("smooth_min", &c.smooth_min, "", 1e6, "sharpness of the smooth minimum over global GPs"),
      whole("global_neighbours", &c.global_neighbours, 1, 27, "global GPs combined per query"),
      positive("query_radius", &c.query_radius, "m", kMaxRange,
               "a point farther from every global GP leaf is unobserved"),
      positive("gradient_scale", &c.gradient_scale, "", 1e3,
               "lengthscale of the soft nearest crossing for gradients, in GP lengthscales"),
      number("recon_min_weight", &c.recon_min_weight, "", 0.0, 1e9,
             "fused weight below which a voxel is not part of the surface"),
      number("min_range", &c.min_range, "m", 0.0, kMaxRange, "points nearer the camera are ignored"),
      positive("max_range", &c.max_range, "m", kMaxRange, "points farther from the camera are ignored"),
  };
}

FieldTable tsdf_fields(TsdfConfig& c) {
  Field voxel = number("voxel", &c.voxel, "m", kMinVoxel, kMaxVoxel, "voxel size (`--voxel`)");
  Field carving = flag("space_carving", &c.space_carving, "carve the observed free space in view");
  carving.aliases = {"carving"};
  return {
      voxel,
      positive("truncation", &c.truncation, "m", kMaxVoxel * 10,
               "truncation distance (`--voxel` keeps it at 3 voxels)"),
      carving,
      number("weight_cap", &c.weight_cap, "", 0.0, 1e9, "per-update weight ceiling (0: none)"),
      number("min_weight", &c.min_weight, "", 0.0, 1e9, "weight needed for queries and the surface"),
      number("min_range", &c.min_range, "m", 0.0, kMaxRange, "points nearer the camera are ignored"),
      positive("max_range", &c.max_range, "m", kMaxRange, "points farther from the camera are ignored"),
  };
}

FieldTable open3d_fields(Open3dTsdfConfig& c) {
  return {
      number("voxel", &c.voxel, "m", kMinVoxel, kMaxVoxel, "voxel size (`--voxel`)"),
      positive("truncation", &c.truncation, "m", kMaxVoxel * 10,
               "truncation distance (`--voxel` keeps it at 3 voxels)"),
      number("min_range", &c.min_range, "m", 0.0, kMaxRange, "points nearer the camera are ignored"),
      positive("max_range", &c.max_range, "m", kMaxRange, "points farther from the camera are ignored"),
  };
}

FieldTable raster_fields(RasterConfig& c) {
  return {
      whole("azimuth_bins", &c.azimuth_bins, 1, 36000, "bins over 360 degrees"),
      number("band_min", &c.band_min, "m", -kMaxRange, kMaxRange, "obstacle band bottom, above the ground"),
      number("band_max", &c.band_max, "m", -kMaxRange, kMaxRange, "obstacle band top, above the ground"),
      positive("row_height", &c.row_height, "m", kMaxRange,
               "cylinder row height; rows x `azimuth_bins` at most 4,000,000"),
      positive("max_range", &c.max_range, "m", kMaxRange, "horizontal range of the rasters"),
  };
}

FieldTable metrics_fields(eval::MetricsConfig& c) {
  return {
      number("ghost_tolerance", &c.ghost_tolerance, "m", 0.0, kMaxRange,
             "a cell this much closer than the truth is a ghost (default: 2 voxels)"),
      number("edge_jump", &c.edge_jump, "m", 0.0, kMaxRange,
             "a truth jump above this to a neighbour marks a silhouette edge"),
  };
}

FieldTable edf_raster_fields(EdfRasterConfig& c) {
  return {
      positive("sample_radius", &c.sample_radius, "m", kMaxRange, "circle of EDF query points"),
      positive("hit_tolerance", &c.hit_tolerance, "m", 10.0, "a traced ray hits below this distance"),
      whole("max_steps", &c.max_steps, 1, 1000000, "sphere-tracing steps before a ray gives up"),
      positive("max_range", &c.max_range, "m", kMaxRange, "ray length (default: raster.max_range)"),
  };
}

FieldTable listen_fields(ListenSettings& c) {
  audio::ListenConfig& l = c.stream;
  return {
      number("period", &l.period_s, "s", 0.1, 60.0, "one sweep round the circle (run --listen)"),
      number("pause", &l.pause_s, "s", 0.0, 60.0, "silence after each sweep"),
      {"mode", Choice{{"world_locked", "head_locked"},
                      [&l] { return l.mode == audio::ListenMode::WorldLocked ? 0 : 1; },
                      [&l](int i) { l.mode = i == 0 ? audio::ListenMode::WorldLocked : audio::ListenMode::HeadLocked; }},
       "", {}, "world_locked: obstacles stay put as the head turns; head_locked: they turn with it"},
      number("rt60", &c.rt60, "s", 0.05, 3.0, "reverberation of the synthesised room (no --brir)"),
      flag("woosh", &c.woosh, "unscanned sectors play the woosh"),
  };
}

}  // namespace sonomap::harness
