// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the scenario and render tests: scratch directories and small files.
#pragma once

#include "harness/support/errors.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace sonomap::test {

// A fresh directory under the system temp dir, removed at the end of the test.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& label) {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("sonomap-" + label + "-" + std::to_string(::getpid()) + "-" +
             std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path file = path_ / name;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }

 private:
  std::filesystem::path path_;
};

// Runs `action`, which must throw InputError; returns its message.
template <typename Action>
std::string input_error_of(Action action) {
  try {
    action();
  } catch (const harness::InputError& e) {
    return e.what();
  }
  FAIL("expected an InputError, but nothing was thrown");
  return {};
}

inline std::filesystem::path shipped(const std::string& relative) {
  return std::filesystem::path(SONOMAP_SOURCE_DIR) / relative;
}

}  // namespace sonomap::test
