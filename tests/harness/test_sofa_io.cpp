// SPDX-License-Identifier: GPL-3.0-or-later
// SOFA files: what we write, libmysofa loads back sample for sample; measured HRIR sets load;
// malformed files end in a clear error, never a crash.
#include "harness/formats/sofa_io.hpp"
#include "harness/support/errors.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <random>
#include <unistd.h>

// libmysofa 1.3.1 itself leaks ~1 KiB of attribute strings when it rejects some malformed files
// (bad/ corpus); that is the library's, not ours: keep LeakSanitizer (SONOMAP_SANITIZE) quiet
// about it and only it. A no-op hook in builds without the sanitizer.
extern "C" const char* __lsan_default_suppressions() { return "leak:libmysofa.so\n"; }

namespace fs = std::filesystem;
using namespace sonomap;
using namespace sonomap::harness;

namespace {

// A set whose samples are all different (seeded), so a transposed or shifted read shows.
audio::BrirSet random_set(double rate, const std::vector<double>& azimuths,
                          const std::vector<double>& distances, size_t length) {
  std::mt19937_64 rng(42);
  std::vector<audio::BinauralIr> irs(azimuths.size() * distances.size());
  for (auto& ir : irs)
    for (auto* ear : {&ir.left, &ir.right})
      for (size_t i = 0; i < length; ++i)
        ear->push_back(static_cast<float>(static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5));
  return audio::BrirSet(rate, audio::BrirGrid{azimuths, distances}, std::move(irs));
}

}  // namespace

TEST_CASE("SOFA round trip: written with netCDF, loaded by libmysofa, samples equal", "[sofa]") {
  const sonomap::test::ScratchDir scratch("sofa-roundtrip");
  const fs::path& dir = scratch.path();
  const std::vector<double> azimuths{-177.0, -90.0, 0.0, 3.0, 90.0, 180.0};
  const audio::BrirSet set = random_set(48000.0, azimuths, {1.2}, 300);
  std::vector<audio::BinauralIr> irs;
  for (size_t a = 0; a < azimuths.size(); ++a) irs.push_back(set.at(0, a));
  const fs::path file = dir / "one.sofa";
  write_brir_sofa(file, 48000.0, 1.2, azimuths, irs);

  const SofaContents back = read_sofa(file);
  CHECK(back.sample_rate == 48000.0);
  CHECK(back.room_type == "reverberant");
  REQUIRE(back.irs.size() == azimuths.size());
  const double pi = 3.14159265358979323846;
  for (size_t i = 0; i < azimuths.size(); ++i) {
    const double a = azimuths[i] * pi / 180.0;
    CHECK(back.source_positions[i].x() == Approx(1.2 * std::cos(a)).margin(1e-4));
    CHECK(back.source_positions[i].y() == Approx(1.2 * std::sin(a)).margin(1e-4));
    CHECK(back.source_positions[i].z() == Approx(0.0).margin(1e-4));
    CHECK(back.irs[i].left == irs[i].left);  // exact: float -> double -> float
    CHECK(back.irs[i].right == irs[i].right);
  }
  fs::remove_all(dir);
}

TEST_CASE("a BRIR directory round trip keeps the grid and every sample, rates are converted",
          "[sofa]") {
  const sonomap::test::ScratchDir scratch("sofa-dir");
  const fs::path& dir = scratch.path();
  const auto grid = audio::BrirGrid::paper();
  const std::vector<double> azimuths{-90.0, 0.0, 90.0, 180.0};
  const audio::BrirSet set = random_set(48000.0, azimuths, grid.distances_m, 64);
  write_brir_directory(dir / "set", set);
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir / "set")) files += e.path().extension() == ".sofa";
  CHECK(files == 10);
  const audio::BrirSet back = read_brir_directory(dir / "set", 48000.0);
  REQUIRE(back.distance_count() == 10);
  REQUIRE(back.azimuth_count() == 4);
  for (size_t d = 0; d < 10; ++d) {
    CHECK(back.grid().distances_m[d] == Approx(grid.distances_m[d]).margin(1e-4));
    for (size_t a = 0; a < 4; ++a) {
      CHECK(back.at(d, a).left == set.at(d, a).left);
      CHECK(back.at(d, a).right == set.at(d, a).right);
    }
  }
  // Read at another output rate: libsamplerate converts, the length scales with the rate.
  const audio::BrirSet at_96k = read_brir_directory(dir / "set", 96000.0);
  CHECK(at_96k.sample_rate() == 96000.0);
  CHECK(static_cast<double>(at_96k.ir_length()) == Approx(128.0).margin(2.0));
  fs::remove_all(dir);
}

TEST_CASE("bad BRIR directories: empty, a missing distance, a mixed sample rate", "[sofa]") {
  const sonomap::test::ScratchDir scratch("sofa-bad");
  const fs::path& dir = scratch.path();
  fs::create_directories(dir / "empty");
  CHECK_THROWS_WITH(read_brir_directory(dir / "empty", 48000.0), Catch::Contains("no .sofa files"));
  const auto grid = audio::BrirGrid::paper();
  const audio::BrirSet set = random_set(48000.0, {0.0, 90.0}, grid.distances_m, 32);
  write_brir_directory(dir / "set", set);
  fs::remove(dir / "set" / brir_file_name(2.0));
  CHECK_THROWS_WITH(read_brir_directory(dir / "set", 48000.0),
                    Catch::Contains("missing BRIRs for distance 2.0"));
  // Put 2.0 m back, at 44.1 kHz.
  std::vector<audio::BinauralIr> irs{set.at(4, 0), set.at(4, 1)};
  write_brir_sofa(dir / "set" / brir_file_name(2.0), 44100.0, 2.0, {0.0, 90.0}, irs);
  CHECK_THROWS_WITH(read_brir_directory(dir / "set", 48000.0), Catch::Contains("sample rate"));
  // A file that is not HDF5 at all.
  std::ofstream(dir / "set" / brir_file_name(2.0)) << "not a SOFA file\n";
  CHECK_THROWS_AS(read_brir_directory(dir / "set", 48000.0), InputError);
  fs::remove_all(dir);
}

TEST_CASE("the measured MIT KEMAR set loads as 710 directions, resampled to 48 kHz", "[sofa]") {
  const audio::HrirSet kemar = read_hrir_set("/usr/share/libmysofa/default.sofa", 48000.0);
  CHECK(kemar.directions.size() == 710);
  CHECK(kemar.sample_rate == 48000.0);
  // 512 taps at 44.1 kHz -> about 557 at 48 kHz.
  CHECK(static_cast<double>(kemar.irs.front().left.size()) == Approx(512.0 * 48000.0 / 44100.0).margin(3));
  // A source on the left: more energy at the left ear.
  const auto& left_side = kemar.irs[kemar.nearest({0.0, 1.0, 0.0})];
  double l = 0, r = 0;
  for (size_t i = 0; i < left_side.left.size(); ++i)
    l += left_side.left[i] * left_side.left[i], r += left_side.right[i] * left_side.right[i];
  CHECK(l > 2.0 * r);
}

TEST_CASE("every malformed SOFA file gives a clear error or a clean load, never a crash",
          "[sofa]") {
  const fs::path bad_dir = fs::path(SONOMAP_SHARED_DIR) / "data" / "sofa" / "bad";
  REQUIRE(fs::is_directory(bad_dir));
  int files = 0, refused = 0;
  for (const auto& entry : fs::directory_iterator(bad_dir)) {
    if (entry.path().extension() != ".sofa") continue;
    ++files;
    INFO(entry.path().filename().string());
    try {
      const SofaContents s = read_sofa(entry.path());
      CHECK(!s.irs.empty());  // a clean load is a usable one
    } catch (const InputError& e) {
      ++refused;
      CHECK(std::string(e.what()).find(entry.path().filename().string()) != std::string::npos);
    }
  }
  CHECK(files >= 20);
  CHECK(refused > 0);
}
