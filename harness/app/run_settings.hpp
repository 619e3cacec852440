// SPDX-License-Identifier: GPL-3.0-or-later
// Run keys: the settings of a run that are not part of the scenario file (raster.*, metrics.*,
// edf.*, mapper.*), given as "--set key=value" overrides (README.md, "Run keys").
#pragma once

#include "core/edf_raster.hpp"
#include "core/raster.hpp"
#include "eval/metrics.hpp"
#include "harness/app/mapper_factory.hpp"

#include <string>
#include <vector>

namespace sonomap::harness {

// Run keys (everything that is not part of the scenario file).
struct RunSettings {
  RasterConfig raster;
  eval::MetricsConfig metrics;
  bool ghost_tolerance_set = false;
  std::vector<Setting> mapper;
  // The EDF comparison (edf.*): on by default, every `edf_every`-th evaluated frame (about as
  // costly as integrating a frame: 110 ms median on the smoke room at half resolution).
  bool edf_enabled = true;
  int edf_every = 5;
  int edf_trace_rows = 4;  // rays per bin across the obstacle band (0: the sensor's height)
  EdfRasterConfig edf;
  bool edf_max_range_set = false;  // otherwise the raster's max_range
};

// Splits "key=value" overrides into scenario overrides (returned in `scenario`, in order) and
// run settings (applied to `settings` and validated). Throws InputError naming the override.
void split_overrides(const std::vector<std::string>& overrides, std::vector<std::string>& scenario,
                     RunSettings& settings);

}  // namespace sonomap::harness
