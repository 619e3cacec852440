// SPDX-License-Identifier: GPL-3.0-or-later
// The circle CSV reader (`sonomap sonify CIRCLE.csv`) on arbitrary text.
#include "harness/formats/circle_io.hpp"
#include "harness/support/errors.hpp"

#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    sonomap::harness::parse_circle_csv(text, "fuzz.csv");
  } catch (const sonomap::harness::InputError&) {
  }
  return 0;
}
