// SPDX-License-Identifier: GPL-3.0-or-later
#include "voxel_occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace occupancy {
namespace {

// 21 bits per axis: +-2^20 voxels (52 km at 5 cm) around the world origin.
constexpr int64_t kHalfRange = int64_t{1} << 20;

uint64_t pack(const Eigen::Vector3d& p, double voxel) {
  uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double index = std::floor(p[axis] / voxel);
    if (!(std::abs(index) < kHalfRange))
      throw std::invalid_argument("point " + std::to_string(p[axis]) + " m is outside the map");
    key = (key << 21) | static_cast<uint64_t>(static_cast<int64_t>(index) + kHalfRange);
  }
  return key;
}

Eigen::Vector3d centre(uint64_t key, double voxel) {
  Eigen::Vector3d c;
  for (int axis = 2; axis >= 0; --axis, key >>= 21)
    c[axis] = (static_cast<double>(static_cast<int64_t>(key & 0x1fffff) - kHalfRange) + 0.5) * voxel;
  return c;
}

double number(const sonomap::MapperSetting& s) {
  size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(s.value, &used);
  } catch (const std::exception&) {
  }
  if (used != s.value.size() || !std::isfinite(v))
    throw std::invalid_argument(s.source + ": expected a number, got '" + s.value + "'");
  return v;
}

}  // namespace

void Config::validate() const {
  if (!(voxel >= 0.005 && voxel <= 1.0))
    throw std::invalid_argument("voxel must be in [0.005, 1] m, got " + std::to_string(voxel));
  if (min_hits < 1 || min_hits > 1000)
    throw std::invalid_argument("min_hits must be in [1, 1000], got " + std::to_string(min_hits));
  if (!(min_range >= 0.0 && min_range < max_range && max_range <= 100.0))
    throw std::invalid_argument("need 0 <= min_range < max_range <= 100 m");
}

VoxelOccupancy::VoxelOccupancy(const Config& config) : config_(sonomap::validated(config)) {}

void VoxelOccupancy::integrate(const sonomap::Frame& frame) {
  sonomap::check_pose(frame);  // a bad pose throws std::invalid_argument: the run exits 2
  const auto points = sonomap::world_points(frame, config_.min_range, config_.max_range);
  std::vector<uint64_t> keys;
  keys.reserve(points.size());
  for (const auto& p : points) keys.push_back(pack(p, config_.voxel));  // may throw: map untouched
  for (uint64_t key : keys) ++hits_[key];
}

void VoxelOccupancy::surface_points(const Eigen::Vector3d& center, double radius,
                                    std::vector<Eigen::Vector3f>& out) const {
  std::vector<uint64_t> occupied;
  for (const auto& [key, hits] : hits_)
    if (hits >= config_.min_hits) occupied.push_back(key);
  std::sort(occupied.begin(), occupied.end());  // the same order on every run
  out.clear();
  for (uint64_t key : occupied) {
    const Eigen::Vector3d c = centre(key, config_.voxel);
    if ((c - center).head<2>().norm() <= radius) out.push_back(c.cast<float>());
  }
}

void VoxelOccupancy::query(const std::vector<Eigen::Vector3f>& points,
                           std::vector<sonomap::DistanceQuery>& out) const {
  out.assign(points.size(), sonomap::DistanceQuery{});  // no distance field: nothing observed
}

std::vector<std::pair<std::string, std::string>> VoxelOccupancy::config_entries() const {
  return {{"voxel", std::to_string(config_.voxel)},
          {"min_hits", std::to_string(config_.min_hits)},
          {"min_range", std::to_string(config_.min_range)},
          {"max_range", std::to_string(config_.max_range)}};
}

size_t VoxelOccupancy::memory_bytes() const {
  return hits_.size() * (sizeof(uint64_t) + sizeof(int) + 2 * sizeof(void*));
}

std::unique_ptr<sonomap::Mapper> make_mapper(double voxel,
                                             const std::vector<sonomap::MapperSetting>& settings) {
  Config c;
  if (voxel > 0) c.voxel = voxel;
  for (const auto& s : settings) {
    if (s.key == "voxel") c.voxel = number(s);
    else if (s.key == "min_hits") c.min_hits = static_cast<int>(std::lround(number(s)));
    else if (s.key == "min_range") c.min_range = number(s);
    else if (s.key == "max_range") c.max_range = number(s);
    else
      throw std::invalid_argument(s.source + ": no setting '" + s.key +
                                  "' (settings: voxel, min_hits, min_range, max_range)");
  }
  return std::make_unique<VoxelOccupancy>(c);  // Config::validate throws for bad values
}

}  // namespace occupancy
