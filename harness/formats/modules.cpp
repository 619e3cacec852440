// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/modules.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace sonomap::harness {

namespace {

// The modules lie beside this library, in the build tree (harness/) and installed (lib/),
// and are opened by their full path there. A bare name would be looked up through the RUNPATH
// of the library calling dlopen, which is not this one under the sanitizers: their dlopen
// interceptor calls dlopen from their own runtime, and every sanitizer run that needed a
// module failed to find it. The table's type is the one the module was built with (same build).
std::string beside_this_library(const char* library) {
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&beside_this_library), &info) != 0 && info.dli_fname != nullptr) {
    const std::filesystem::path self(info.dli_fname);
    if (self.has_parent_path()) return (self.parent_path() / library).string();
  }
  return library;
}

template <typename Table>
const Table* load(const char* library, const char* entry_name) {
  const std::string path = beside_this_library(library);
  void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!module) throw std::runtime_error("cannot load " + path + ": " + dlerror());
  using Entry = const Table* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(module, entry_name));
  if (!entry) throw std::runtime_error(path + " has no " + entry_name + ": " + dlerror());
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
