// SPDX-License-Identifier: GPL-3.0-or-later
// Inputs the fuzz targets found: each is refused with exit status 2, promptly and cleanly.
#include "test_safety_support.hpp"

namespace fs = std::filesystem;
using namespace sonomap::test;

TEST_CASE("a corrupt SOFA file on which libmysofa loops is refused with exit 2", "[safety]") {
  // fuzz_sofa's finding: one mutated byte in a valid two-direction file; libmysofa 1.3.1's
  // mysofa_load seeks without end on it, netCDF's HDF5 reader refuses it.
  const fs::path corrupt = shipped("tests/harness/data/corrupt_hdf5_hang.sofa");
  ScratchDir scratch("safety-sofa");
  const auto result = run_sonomap({"--quiet", "brir", "--hrir", corrupt.string(), "--out",
                                   (scratch.path() / "brirs").string()});
  INFO(result.output);
  CHECK(result.status == 2);
  CHECK(result.output.find("not a SOFA (netCDF-4/HDF5) file") != std::string::npos);
  CHECK(fs::is_empty(scratch.path()));
}
