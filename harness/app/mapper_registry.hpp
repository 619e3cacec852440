// SPDX-License-Identifier: GPL-3.0-or-later
// Mappers by name. The built-in ones (vdb_gpdf, tsdf, open3d, depth_only) are registered here
// exactly like a user's: a program built on sonomap calls register_mapper() before cli_main()
// and its mapper is selectable with `--mapper NAME` and in sweep variants (docs/sdk.md).
#pragma once

#include "core/mapper.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace sonomap::harness {

// A setting as the user wrote it: the field (without "mapper."), its value, and where it came
// from (e.g. "--set mapper.voxel=0.1"), for error messages.
struct Setting {
  std::string key;
  std::string value;
  std::string source;
};

// Builds a fresh mapper for one run. voxel > 0 is the run's `--voxel` (0: the mapper's own
// default); settings are the run's "mapper.<key>=value" entries in the order given. A factory
// rejects an unknown key or a bad value by throwing std::invalid_argument (or InputError) with
// a message naming the setting's source: the run stops with exit status 2.
using MapperFactory =
    std::function<std::unique_ptr<Mapper>(double voxel, const std::vector<Setting>& settings)>;

// Adds a mapper under `name` (letters, digits, '_' and '-'). Call it before cli_main(), from
// one thread. Throws std::invalid_argument for an empty or malformed name, a name already
// taken (the built-ins included) or an empty factory.
void register_mapper(const std::string& name, MapperFactory factory);

// The names `--mapper` accepts: the built-ins first, then the registered ones in order.
std::vector<std::string> mapper_names();

// voxel > 0 sets the global voxel size (the `--voxel` option, in [kMinVoxel, kMaxVoxel]; 0: the
// mapper's default). Throws InputError for an unknown mapper, an unknown field or a value out
// of range, naming the setting.
std::unique_ptr<Mapper> make_mapper(const std::string& name, double voxel,
                                    const std::vector<Setting>& settings);

}  // namespace sonomap::harness

namespace sonomap {
using harness::MapperFactory;
using harness::register_mapper;
using MapperSetting = harness::Setting;
}  // namespace sonomap
