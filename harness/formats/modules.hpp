// SPDX-License-Identifier: GPL-3.0-or-later
// Libraries loaded on demand. Three of sonomap's dependencies bring many libraries of their own,
// whose pages a run that does not use them should not hold: Open3D (about 60 libraries: VTK,
// Python, GL, ...; 30 MB resident), ROS1's rosbag_storage (Python, Boost; 4 MB) and netCDF
// (HDF5, curl, GnuTLS, ICU; 7 MB). What sonomap takes from each is in a library of its own,
// opened with dlopen the first time one of its functions is wanted:
//   libsonomap_open3d_io.so   harness/open3d/   the open3d mapper, point cloud files, a k-d tree
//   libsonomap_rosbag_io.so   harness/rosbag/   ROS1 bags in and out
//   libsonomap_netcdf_io.so   harness/netcdf/   SOFA containers opened and written
// Each exports one C function returning its table below. The tables are for the formats
// library's own wrappers (mesh_io, rosbag_io, sofa_io) and the mapper factory; everything else
// calls those.
#pragma once

#include "audio/brir_set.hpp"
#include "core/mapper.hpp"
#include "core/open3d_tsdf.hpp"
#include "harness/formats/rosbag_io.hpp"
#include "harness/formats/sequence_io.hpp"
#include "harness/formats/sofa_io.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <memory>
#include <string>
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

// rosbag_io.hpp's functions, as documented there.
struct RosbagFunctions {
  std::unique_ptr<RecordReader> (*open_reader)(const SequenceSpec& spec);
  std::vector<BagTopic> (*list_topics)(const std::filesystem::path& file);
  std::unique_ptr<RosbagWriter> (*open_writer)(const std::filesystem::path& file, BagCompression compression);
};

struct NetcdfFunctions {
  // nc_open's status for the file (0: it opens as netCDF-4/HDF5), and the text of a status.
  int (*open_status)(const std::filesystem::path& file);
  std::string (*status_text)(int status);
  // Writes one SOFA file in place (sofa_io.hpp's write_brir_sofa stages and renames it).
  void (*write_brir_sofa)(const std::filesystem::path& file, double sample_rate, double distance_m,
                          const std::vector<double>& azimuths_deg,
                          const std::vector<audio::BinauralIr>& irs, const SofaMetadata& meta);
};

// The tables, each from its library opened on the first call (thread-safe; never closed).
// Throw std::runtime_error naming the library and the loader's reason when it cannot be opened.
const Open3dFunctions& open3d_functions();
const RosbagFunctions& rosbag_functions();
const NetcdfFunctions& netcdf_functions();

}  // namespace sonomap::harness

// The libraries' entry points, found by name.
extern "C" const sonomap::harness::Open3dFunctions* sonomap_open3d_functions();
extern "C" const sonomap::harness::RosbagFunctions* sonomap_rosbag_functions();
extern "C" const sonomap::harness::NetcdfFunctions* sonomap_netcdf_functions();
