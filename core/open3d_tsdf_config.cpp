// SPDX-License-Identifier: GPL-3.0-or-later
// The open3d mapper's settings, checked without Open3D: the mapper itself is in its own library
// (sonomap_open3d, loaded only by the runs that use it), its settings are read by every run.
#include "core/open3d_tsdf.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap {

void Open3dTsdfConfig::validate() const {
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  auto fail = [](const std::string& what) { throw std::invalid_argument("Open3dTsdfConfig: " + what); };
  if (!positive(voxel)) fail("voxel must be > 0, got " + std::to_string(voxel));
  if (!positive(truncation)) fail("truncation must be > 0, got " + std::to_string(truncation));
  if (!(min_range >= 0.0 && positive(max_range) && min_range < max_range))
    fail("need 0 <= min_range < max_range");
}

}  // namespace sonomap
