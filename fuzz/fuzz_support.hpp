// SPDX-License-Identifier: GPL-3.0-or-later
// Shared by the fuzz targets: a private scratch folder per process and the rule they check.
// A reader given any bytes must either succeed or throw InputError (exit 2 with a message);
// any other exception, a crash, a leak or undefined behaviour is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace sonomap::fuzz {

inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("sonomap-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::filesystem::path write_file(const std::string& name, const std::string& bytes) {
  const std::filesystem::path file = scratch() / name;
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  return file;
}

}  // namespace sonomap::fuzz
