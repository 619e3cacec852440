// SPDX-License-Identifier: GPL-3.0-or-later
// A progress bar on stderr, shown only on a terminal and never with --quiet.
#pragma once

#include <chrono>
#include <string>

namespace sonomap::harness {

class Progress {
 public:
  Progress(std::string label, long total, bool quiet);
  ~Progress();
  void update(long done);
  void finish();

 private:
  std::string label_;
  long total_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace sonomap::harness
