// SPDX-License-Identifier: GPL-3.0-or-later
// Builds a mapper by name with "mapper.<field>=value" settings, so an A/B run swaps the mapper
// and nothing else changes. The settable fields are the mapper config's field table
// (harness/app/config_fields.hpp): the same table records the config in summary.json.
#pragma once

#include "core/mapper.hpp"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace sonomap::harness {

// A setting as the user wrote it: the field (without "mapper."), its value, and where it came
// from (e.g. "--set mapper.voxel=0.1"), for error messages.
struct Setting {
  std::string key;
  std::string value;
  std::string source;
};

// The names `--mapper` accepts.
std::vector<std::string> mapper_names();

// voxel > 0 sets the global voxel size (the `--voxel` option; 0: the mapper's default). Throws
// InputError for an unknown mapper, an unknown field or a value out of range, naming the setting.
std::unique_ptr<Mapper> make_mapper(const std::string& name, double voxel,
                                    const std::vector<Setting>& settings);

// The mapper's whole config, every field of its table with its value (summary.json's
// mapper_config), after "mapper": name.
std::vector<std::pair<std::string, std::string>> mapper_config_entries(const Mapper& mapper);

// The mapper's (global) voxel size in metres; 0 for a mapper without a grid.
double mapper_voxel(const Mapper& mapper);
// Estimated bytes of the mapper's map over `surface_area` m^2 of surfaces: VDB leaves of 8^3
// (distance, weight) voxels along the surfaces, two deep for the truncation band. On the smoke
// scene (84 m^2) at 0.05 m it says 4.4 MB; `bench map` measured a peak of 4.5 MB (VDB-GPDF)
// and 4.3 MB (TSDF) after 60 frames.
double estimated_map_bytes(const Mapper& mapper, double surface_area);

// Every mapper's settings with default, bounds and meaning (docs/settings.md, `--help`).
std::string mapper_settings_markdown();
std::string mapper_settings_help();

}  // namespace sonomap::harness
