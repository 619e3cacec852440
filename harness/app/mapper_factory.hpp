// SPDX-License-Identifier: GPL-3.0-or-later
// Builds a mapper by name with "mapper.<field>=value" settings, so an A/B run swaps the mapper
// and nothing else changes. The settable fields are the mapper config's field table
// (harness/app/config_fields.hpp): the same table records the config in summary.json.
#pragma once

#include "harness/app/mapper_registry.hpp"

#include <string>
#include <utility>
#include <vector>

namespace sonomap::harness {

// The built-in mappers with their factories, in the order `--mapper` lists them.
// make_mapper() and mapper_names() (mapper_registry.hpp) serve them and the ones a program
// registers.
std::vector<std::pair<std::string, MapperFactory>> builtin_mappers();

// The mapper's whole config, every field of its table with its value (summary.json's
// mapper_config), after "mapper": name. A registered mapper gives its config_entries().
std::vector<std::pair<std::string, std::string>> mapper_config_entries(const Mapper& mapper);

// The mapper's (global) voxel size in metres; 0 for a mapper without a grid. A registered
// mapper gives its config_entries() "voxel", if any.
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
