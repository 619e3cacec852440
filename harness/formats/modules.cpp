// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/modules.hpp"

#include <dlfcn.h>

#include <stdexcept>
#include <string>

namespace sonomap::harness {

namespace {

// dlopen searches the RUNPATH of the library that calls it, this one: the build tree's harness
// folder, or the installed library folder. So the modules are found wherever sonomap's own
// libraries are. The table's type is the one the module was built with (same build).
template <typename Table>
const Table* load(const char* library, const char* entry_name) {
  void* module = dlopen(library, RTLD_NOW | RTLD_LOCAL);
  if (!module) throw std::runtime_error(std::string("cannot load ") + library + ": " + dlerror());
  using Entry = const Table* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(module, entry_name));
  if (!entry) throw std::runtime_error(std::string(library) + " has no " + entry_name + ": " + dlerror());
  return entry();
}

}  // namespace

// A throw leaves the static uninitialised: the next call tries again.
const Open3dFunctions& open3d_functions() {
  static const Open3dFunctions* const table =
      load<Open3dFunctions>("libsonomap_open3d_io.so", "sonomap_open3d_functions");
  return *table;
}

const RosbagFunctions& rosbag_functions() {
  static const RosbagFunctions* const table =
      load<RosbagFunctions>("libsonomap_rosbag_io.so", "sonomap_rosbag_functions");
  return *table;
}

const NetcdfFunctions& netcdf_functions() {
  static const NetcdfFunctions* const table =
      load<NetcdfFunctions>("libsonomap_netcdf_io.so", "sonomap_netcdf_functions");
  return *table;
}

}  // namespace sonomap::harness
