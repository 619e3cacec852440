// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/open3d_module.hpp"

#include <dlfcn.h>

#include <stdexcept>
#include <string>

namespace sonomap::harness {

namespace {

constexpr const char* kModule = "libsonomap_open3d_io.so";

// dlopen searches this library's RUNPATH (the build tree's module directory, or the installed
// library directory), so the module is found wherever sonomap's own libraries are.
const Open3dFunctions* load() {
  void* module = dlopen(kModule, RTLD_NOW | RTLD_LOCAL);
  if (!module) throw std::runtime_error(std::string("cannot load Open3D support: ") + dlerror());
  using Entry = const Open3dFunctions* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(module, "sonomap_open3d_functions"));
  if (!entry) throw std::runtime_error(std::string(kModule) + " has no sonomap_open3d_functions: " + dlerror());
  return entry();
}

}  // namespace

const Open3dFunctions& open3d_functions() {
  static const Open3dFunctions* const functions = load();  // a throw leaves it for the next call
  return *functions;
}

}  // namespace sonomap::harness
