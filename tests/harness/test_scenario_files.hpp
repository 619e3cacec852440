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

// A valid scenario; the comments give the 1-based line numbers the tests refer to.
inline const std::string kBase =
    "name: probe\n"                                              // 1
    "frames: 3\n"                                                // 2
    "sensor:\n"                                                  // 3
    "  intrinsics: {fx: 525, fy: 525, cx: 319.5, cy: 239.5}\n"   // 4
    "  min_range: 0.3\n"                                         // 5
    "  max_range: 5.0\n"                                         // 6
    "body:\n"                                                    // 7
    "  interpolation: linear_slerp\n"                            // 8
    "  keyframes:\n"                                             // 9
    "    - {time: 0, position: [0, 0, 1.5], yaw: 0}\n"           // 10
    "    - {time: 1, position: [1, 0, 1.5], yaw: 90}\n"          // 11
    "static:\n"                                                  // 12
    "  - name: room\n"                                           // 13
    "    room: {size: [4, 4, 2.5]}\n";                           // 14

// kBase with lines first..last (1-based) replaced by `text` (which may hold several lines).
inline std::string with_lines(int first, int last, const std::string& text) {
  std::string out;
  int number = 1;
  for (std::size_t start = 0; start < kBase.size(); ++number) {
    const std::size_t end = kBase.find('\n', start);
    if (number == first) out += text + "\n";
    if (number < first || number > last) out += kBase.substr(start, end - start + 1);
    start = end + 1;
  }
  return out;
}

inline std::string with_line(int line, const std::string& text) { return with_lines(line, line, text); }

inline std::filesystem::path shipped(const std::string& relative) {
  return std::filesystem::path(SONOMAP_SOURCE_DIR) / relative;
}

}  // namespace sonomap::test
