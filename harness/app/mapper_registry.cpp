// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/mapper_registry.hpp"

#include "harness/app/mapper_factory.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/fields.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace sonomap::harness {
namespace {

using Entry = std::pair<std::string, MapperFactory>;

// The built-ins first, so a user's registration cannot shadow one of them.
std::vector<Entry>& entries() {
  static std::vector<Entry> list = builtin_mappers();
  return list;
}

const Entry* find(const std::string& name) {
  const auto& list = entries();
  const auto it = std::find_if(list.begin(), list.end(), [&](const Entry& e) { return e.first == name; });
  return it == list.end() ? nullptr : &*it;
}

bool valid_name(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-';
  });
}

}  // namespace

void register_mapper(const std::string& name, MapperFactory factory) {
  if (!valid_name(name))
    throw std::invalid_argument("register_mapper: '" + name +
                                "' is not a mapper name (letters, digits, '_' and '-')");
  if (!factory) throw std::invalid_argument("register_mapper: '" + name + "' has no factory");
  if (find(name)) throw std::invalid_argument("register_mapper: '" + name + "' is already registered");
  entries().emplace_back(name, std::move(factory));
}

std::vector<std::string> mapper_names() {
  std::vector<std::string> names;
  for (const Entry& e : entries()) names.push_back(e.first);
  return names;
}

std::unique_ptr<Mapper> make_mapper(const std::string& name, double voxel,
                                    const std::vector<Setting>& settings) {
  if (voxel != 0.0 && !(voxel >= kMinVoxel && voxel <= kMaxVoxel))
    throw InputError("--voxel " + number_text(voxel) + ": expected a voxel size in [" +
                     number_text(kMinVoxel) + ", " + number_text(kMaxVoxel) + "] m");
  const Entry* entry = find(name);
  if (!entry) {
    std::string names;
    for (const auto& n : mapper_names()) names += (names.empty() ? "" : ", ") + n;
    throw InputError("--mapper " + name + ": unknown mapper (known: " + names + ")");
  }
  std::unique_ptr<Mapper> mapper;
  try {
    mapper = entry->second(voxel, settings);
  } catch (const std::invalid_argument& e) {
    throw InputError("mapper '" + name + "': " + e.what());
  }
  if (!mapper) throw std::runtime_error("mapper '" + name + "': its factory returned no mapper");
  return mapper;
}

}  // namespace sonomap::harness
