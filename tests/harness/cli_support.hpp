// SPDX-License-Identifier: GPL-3.0-or-later
// Running the sonomap executable from tests (SONOMAP_EXE is set by ctest), without a shell.
#pragma once

#include "harness/support/subprocess.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace sonomap::test {

struct CliResult {
  int status = -1;
  std::string output;  // stdout and stderr together
};

inline CliResult run_sonomap(const std::vector<std::string>& arguments) {
  const char* exe = std::getenv("SONOMAP_EXE");
  if (!exe) FAIL("SONOMAP_EXE is not set: run this test under ctest");
  std::vector<std::string> argv{exe};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  CliResult result;
  result.status = harness::run_program(argv, &result.output);
  return result;
}

inline std::string text_of(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Nothing named like `out` (no partial directory or file either) exists beside it.
inline bool nothing_written(const std::filesystem::path& out) {
  const std::string stem = out.filename().string();
  for (const auto& entry : std::filesystem::directory_iterator(out.parent_path()))
    if (entry.path().filename().string().rfind(stem, 0) == 0) return false;
  return true;
}

}  // namespace sonomap::test
