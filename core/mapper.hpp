// SPDX-License-Identifier: GPL-3.0-or-later
// One interface for every map, so an A/B run swaps the mapper and nothing else. This is the
// public contract a mapper of your own implements (docs/sdk.md; frames: docs/conventions.md).
//
// How a run drives a mapper: a factory (harness/app/mapper_registry.hpp) builds one fresh
// mapper per run; config_entries() is read once; then for every frame in order, integrate()
// and last_stage_times(); on evaluated frames surface_spans_in_band() around the listener
// (and surface_points_in_band() for a video's top view, query() when the EDF comparison is
// on); surface_points() for a sweep's room; surface_mesh() once at the end; memory_bytes() by
// `bench map`.
// Thread-safety: the harness never calls one mapper from two threads at once, and const calls
// never overlap integrate(). A mapper may use TBB inside its calls (`--threads` caps it), but
// its results must not depend on the thread count or on timing: same frames, same output.
// Errors: std::invalid_argument for bad input (an unusable frame, a bad setting in the
// factory) stops the run with exit status 2 and a message naming the frame or setting; any
// other exception is a failure (exit status 1). A mapper never prints and never touches files.
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sonomap {

// Result of a distance query at one point.
struct DistanceQuery {
  bool observed = false;           // false: the map knows nothing here; distance is not guessed
  float distance = 0.0f;           // metres (unsigned for VDB-GPDF's global field)
  Eigen::Vector3f gradient = Eigen::Vector3f::Zero();  // unit, pointing away from the surface
  float variance = 0.0f;
};

// Wall time of the mapper's own stages in the last integrate(), milliseconds.
struct StageTimes {
  std::vector<std::pair<std::string, double>> stages;
};

class Mapper {
 public:
  virtual ~Mapper() = default;
  // The name results record (summary.json "mapper"), e.g. "vdb_gpdf".
  virtual std::string name() const = 0;
  // Fuses one frame: frame.points_camera (valid returns only, camera optical frame: x right,
  // y down, z forward, metres) placed with frame.world_T_camera, the localisation estimate
  // (world z up). frame.depth is the same data as an image. The *_true poses are for ground
  // truth only: a mapper must not read them. Frames with invalid poses or points are rejected
  // with std::invalid_argument, map untouched (check_pose() and world_points() below help).
  virtual void integrate(const Frame& frame) = 0;
  // Replaces `out` with surface samples in the world within `radius` (horizontal distance) of
  // `center` (the listener's estimated position), dense enough that neighbouring samples of one
  // continuous surface are at most about half a voxel apart. The rasters take the samples in
  // the obstacle band; their order must be the same on every run.
  virtual void surface_points(const Eigen::Vector3d& center, double radius,
                              std::vector<Eigen::Vector3f>& out) const = 0;
  // What the rasters read every evaluated frame: the samples of surface_points() whose height
  // z lies in [z_min, z_max] (world), the obstacle band, in surface_points()' order. A map that
  // keeps its samples by place can skip the floor and the ceiling without reading them.
  // Returning samples outside the band is allowed (the rasteriser ignores them); dropping one
  // inside is not. The default returns all of surface_points().
  virtual void surface_points_in_band(const Eigen::Vector3d& center, double radius, double /*z_min*/,
                                      double /*z_max*/, std::vector<Eigen::Vector3f>& out) const {
    surface_points(center, radius, out);
  }
  // The same samples read in place, which is what the rasters call: `spans` is replaced by
  // runs of samples that, one after the other, hold every sample of surface_points_in_band()
  // in its order. Samples outside the band or the radius may lie between them (the rasteriser
  // ignores those). The spans stay valid until the next non-const call. A map that keeps its
  // samples by leaf hands over whole leaves without copying them; the default copies
  // surface_points_in_band() into `scratch` and hands over that.
  virtual void surface_spans_in_band(const Eigen::Vector3d& center, double radius, double z_min,
                                     double z_max, std::vector<SampleSpan>& spans,
                                     std::vector<Eigen::Vector3f>& scratch) const {
    surface_points_in_band(center, radius, z_min, z_max, scratch);
    spans.assign(1, SampleSpan{scratch.data(), scratch.size()});
  }
  // Distance field queries (batched, world points): `out` gets exactly one answer per point.
  // Maps without a field answer observed = false everywhere.
  virtual void query(const std::vector<Eigen::Vector3f>& points,
                     std::vector<DistanceQuery>& out) const = 0;
  // The stages of the last integrate() with their times (timings.csv "map.<stage>").
  virtual StageTimes last_stage_times() const { return {}; }
  // The whole surface as a triangle mesh in the world (the harness writes it as PLY).
  // Maps without a mesh leave both empty.
  virtual void surface_mesh(std::vector<Eigen::Vector3f>& vertices,
                            std::vector<Eigen::Vector3i>& triangles) const {
    vertices.clear();
    triangles.clear();
  }
  // The configuration as (key, value) text, for summary.json. Only mappers registered from
  // outside use it (the built-in ones are recorded from their settings tables); a "voxel"
  // entry (metres) sets the ghost tolerance of the metrics to two voxels.
  virtual std::vector<std::pair<std::string, std::string>> config_entries() const { return {}; }
  // Bytes held by the map (grids, caches); 0 if the map does not know.
  virtual size_t memory_bytes() const { return 0; }
};

// A config checked by its validate() (which throws std::invalid_argument), for use in a
// mapper's member initialisers before anything is built from it.
template <typename Config>
const Config& validated(const Config& config) {
  config.validate();
  return config;
}

// Rejects a pose a mapper must not fuse: non-finite, or a rotation that is not orthonormal
// with determinant +1 (tolerance 1e-3). Throws std::invalid_argument naming the frame.
inline void check_pose(const Frame& frame) {
  const Eigen::Matrix4d m = frame.world_T_camera.matrix();
  if (!m.allFinite())
    throw std::invalid_argument("frame " + std::to_string(frame.index) +
                                ": world_T_camera has a NaN or infinite entry");
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double err = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (err > 1e-3 || r.determinant() < 0.0)
    throw std::invalid_argument("frame " + std::to_string(frame.index) +
                                ": world_T_camera rotation is not orthonormal (|R^T R - I| = " +
                                std::to_string(err) + ", det = " +
                                std::to_string(r.determinant()) + ")");
}

// Whether the frame carries a depth image that a projective integrator can read: pixels and
// pinhole intrinsics. Throws std::invalid_argument naming the frame when it has pixels but
// not width x height of them.
inline bool has_depth_image(const Frame& frame) {
  if (frame.depth.empty()) return false;
  if (frame.width <= 0 || frame.height <= 0 ||
      frame.depth.size() != static_cast<size_t>(frame.width) * frame.height)
    throw std::invalid_argument("frame " + std::to_string(frame.index) + ": the depth image has " +
                                std::to_string(frame.depth.size()) + " pixels, not width x height = " +
                                std::to_string(frame.width) + " x " + std::to_string(frame.height));
  return frame.intrinsics.valid();
}

// The frame's points whose distance from the camera lies in [min_range, max_range], in the
// world. Non-finite points are skipped (documented behaviour, not an error) and counted.
inline std::vector<Eigen::Vector3d> world_points(const Frame& frame, double min_range,
                                                 double max_range, size_t* skipped = nullptr) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(frame.points_camera.size());
  size_t bad = 0;
  for (const auto& pc : frame.points_camera) {
    if (!pc.allFinite()) {
      ++bad;
      continue;
    }
    const double r = pc.cast<double>().norm();
    if (r < min_range || r > max_range) continue;
    out.push_back(frame.world_T_camera * pc.cast<double>());
  }
  if (skipped) *skipped = bad;
  return out;
}

}  // namespace sonomap
