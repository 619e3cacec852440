// SPDX-License-Identifier: GPL-3.0-or-later
// Stage timing: every stage is timed at its boundary with the monotonic clock.
#pragma once

#include <chrono>

namespace sonomap {

using StageClock = std::chrono::steady_clock;

// Milliseconds since `start`.
inline double ms_since(StageClock::time_point start) {
  return std::chrono::duration<double, std::milli>(StageClock::now() - start).count();
}

}  // namespace sonomap
