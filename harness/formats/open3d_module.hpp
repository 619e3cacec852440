// SPDX-License-Identifier: GPL-3.0-or-later
// Open3D on demand. Open3D loads about 60 libraries (VTK, Python, assimp, ...) holding some
// 30 MB of resident pages, which a run that does not use it should not pay for. Everything
// sonomap takes from Open3D is in libsonomap_open3d_io.so (harness/open3d/), opened the first
// time one of these functions is wanted: the open3d mapper, point cloud files, and bench map's
// check of Open3D's surface against the TSDF peer's.
#pragma once

#include "core/mapper.hpp"
#include "core/open3d_tsdf.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <memory>
#include <vector>

namespace sonomap::harness {

struct Open3dFunctions {
  // Open3D's ScalableTSDFVolume as a mapper (core/open3d_tsdf.hpp). Throws
  // std::invalid_argument for a bad config.
  std::unique_ptr<Mapper> (*make_mapper)(const Open3dTsdfConfig& config);
  // The settings of a mapper made by make_mapper; nullptr for any other mapper.
  const Open3dTsdfConfig* (*config_of)(const Mapper& mapper);
  // The points of a PLY, PCD or XYZ file (mesh_io.hpp's load_point_cloud reads through it).
  std::vector<Eigen::Vector3f> (*read_point_cloud)(const std::filesystem::path& file);
  // For each point of `from`, the distance to the nearest point of `to` (Open3D's k-d tree);
  // empty when `to` is.
  std::vector<double> (*nearest_distances)(const std::vector<Eigen::Vector3f>& from,
                                           const std::vector<Eigen::Vector3f>& to);
};

// The functions, from the module opened on the first call (thread-safe; never closed). Throws
// std::runtime_error naming the library and the loader's reason when it cannot be opened.
const Open3dFunctions& open3d_functions();

}  // namespace sonomap::harness

// The module's one entry point, found by name.
extern "C" const sonomap::harness::Open3dFunctions* sonomap_open3d_functions();
