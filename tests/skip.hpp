// SPDX-License-Identifier: GPL-3.0-or-later
// Skipping a test that needs something optional (an outside corpus): Catch2 v2 has no SKIP, so
// the reason is printed as a warning and the test case returns. tests/CMakeLists.txt tells CTest
// that output with this marker means "skipped", so `ctest` lists the test as Skipped, not Passed.
#pragma once

#include <catch2/catch.hpp>

#define SONOMAP_SKIP(reason)                        \
  do {                                              \
    WARN("SONOMAP-TEST-SKIPPED: " << reason);       \
    return;                                         \
  } while (false)
