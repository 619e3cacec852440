// SPDX-License-Identifier: GPL-3.0-or-later
// A plain voxel occupancy map: a voxel is occupied once enough depth returns fell into it, and
// its centre is a surface point. No free space, no distance field: the smallest useful Mapper.
#pragma once

#include "core/mapper.hpp"
#include "harness/app/mapper_registry.hpp"

#include <cstdint>
#include <memory>
#include <unordered_map>

namespace occupancy {

struct Config {
  double voxel = 0.05;    // edge length, metres
  int min_hits = 2;       // returns a voxel needs before it counts as surface
  double min_range = 0.3; // returns closer or farther from the camera are ignored, metres
  double max_range = 5.0;
  void validate() const;  // throws std::invalid_argument
};

class VoxelOccupancy : public sonomap::Mapper {
 public:
  explicit VoxelOccupancy(const Config& config);
  std::string name() const override { return "voxel_occupancy"; }
  void integrate(const sonomap::Frame& frame) override;
  void surface_points(const Eigen::Vector3d& center, double radius,
                      std::vector<Eigen::Vector3f>& out) const override;
  void query(const std::vector<Eigen::Vector3f>& points,
             std::vector<sonomap::DistanceQuery>& out) const override;
  std::vector<std::pair<std::string, std::string>> config_entries() const override;
  size_t memory_bytes() const override;

 private:
  Config config_;
  std::unordered_map<uint64_t, int> hits_;  // packed voxel index -> returns counted
};

// The factory handed to sonomap::register_mapper: `--voxel` and the settings
// mapper.voxel, mapper.min_hits, mapper.min_range, mapper.max_range.
std::unique_ptr<sonomap::Mapper> make_mapper(double voxel,
                                             const std::vector<sonomap::MapperSetting>& settings);

}  // namespace occupancy
