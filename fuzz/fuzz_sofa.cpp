// SPDX-License-Identifier: GPL-3.0-or-later
// The SOFA reader (`--brir DIR`, the HRIR file) on arbitrary bytes: as a file read alone and as
// an HRIR set resampled to 48 kHz.
#include "fuzz_support.hpp"
#include "harness/formats/sofa_io.hpp"
#include "harness/support/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = sonomap::fuzz::write_file(
      "input.sofa", std::string(reinterpret_cast<const char*>(data), size));
  try {
    sonomap::harness::read_hrir_set(file, 48000.0);
  } catch (const sonomap::harness::InputError&) {
  }
  return 0;
}
