// SPDX-License-Identifier: GPL-3.0-or-later
// Builds a mapper by name with "mapper.<field>=value" settings, so an A/B run swaps the mapper
// and nothing else changes.
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

// voxel > 0 sets the global voxel size (the `--voxel` option). Throws InputError for an unknown
// mapper, an unknown field or a value out of range, naming the setting.
std::unique_ptr<Mapper> make_mapper(const std::string& name, double voxel,
                                    const std::vector<Setting>& settings);

}  // namespace sonomap::harness
