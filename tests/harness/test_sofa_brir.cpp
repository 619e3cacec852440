// SPDX-License-Identifier: GPL-3.0-or-later
// BRIR files as AES69 SingleRoomMIMOSRIR: written with netCDF, loaded back through libmysofa,
// the mandatory attributes filled, positions in room coordinates that turn back into the
// head-frame grid, every sample equal, and the same bytes on every write.
#include "cli_support.hpp"
#include "harness/formats/sofa_io.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <cmath>

namespace fs = std::filesystem;
using namespace sonomap;
using namespace sonomap::harness;

TEST_CASE("BRIR SOFA files are SingleRoomMIMOSRIR with the mandatory attributes, read back "
          "through libmysofa sample for sample",
          "[sofa]") {
  const sonomap::test::ScratchDir scratch("sofa-brir");
  const std::vector<double> azimuths{-177.0, -90.0, 0.0, 3.0, 90.0, 180.0};
  std::vector<audio::BinauralIr> irs;
  for (size_t a = 0; a < azimuths.size(); ++a) {
    audio::BinauralIr ir{std::vector<float>(200), std::vector<float>(200)};
    for (size_t i = 0; i < 200; ++i) {
      ir.left[i] = std::sin(0.1f * i + a) * 0.3f;
      ir.right[i] = std::cos(0.07f * i * (a + 1)) * 0.2f;
    }
    irs.push_back(ir);
  }
  SofaMetadata meta;
  meta.author_contact = "someone@example.org";
  meta.organization = "a lab";
  meta.room_min = {0, 0, 0};
  meta.room_max = {5, 4, 3};
  meta.listener = {2.0, 1.5, 1.2};
  meta.heading_deg = 30.0;
  const fs::path file = scratch.path() / "one.sofa";
  write_brir_sofa(file, 48000.0, 1.2, azimuths, irs, meta);

  const SofaContents back = read_sofa(file);  // through libmysofa
  const auto& attributes = back.attributes;
  CHECK(attributes.at("Conventions") == "SOFA");
  CHECK(attributes.at("SOFAConventions") == "SingleRoomMIMOSRIR");
  CHECK(attributes.at("DataType") == "FIR-E");
  CHECK(attributes.at("RoomType") == "shoebox");
  CHECK(attributes.at("AuthorContact") == "someone@example.org");
  CHECK(attributes.at("Organization") == "a lab");
  for (const char* mandatory : {"Title", "DateCreated", "DateModified", "APIName", "APIVersion",
                                "License", "DatabaseName", "Version", "SOFAConventionsVersion"})
    CHECK(!attributes.at(mandatory).empty());

  CHECK(back.conventions == "SingleRoomMIMOSRIR");
  CHECK(back.sample_rate == 48000.0);
  REQUIRE(back.irs.size() == azimuths.size());
  const double pi = 3.14159265358979323846;
  for (size_t i = 0; i < azimuths.size(); ++i) {
    // Stored in room coordinates (listener at (2, 1.5, 1.2) facing 30 degrees), read back in the
    // head frame: 1.2 m at the grid azimuth.
    const double a = azimuths[i] * pi / 180.0;
    CHECK(back.source_positions[i].x() == Approx(1.2 * std::cos(a)).margin(1e-5));
    CHECK(back.source_positions[i].y() == Approx(1.2 * std::sin(a)).margin(1e-5));
    CHECK(back.source_positions[i].z() == Approx(0.0).margin(1e-5));
    CHECK(back.irs[i].left == irs[i].left);
    CHECK(back.irs[i].right == irs[i].right);
  }

  const fs::path again = scratch.path() / "again.sofa";
  write_brir_sofa(again, 48000.0, 1.2, azimuths, irs, meta);
  CHECK(sonomap::test::text_of(file) == sonomap::test::text_of(again));  // no timestamps
}
