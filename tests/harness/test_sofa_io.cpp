// SPDX-License-Identifier: GPL-3.0-or-later
// SOFA files: what we write, libmysofa loads back sample for sample; measured HRIR sets load;
// malformed files end in a clear error, never a crash. The malformed files are made here, from
// Debian's own default.sofa (package libmysofa1, in ci/install-deps): nothing outside the
// repository is needed. An outside corpus of malformed files runs too when it is there.
#include "harness/formats/sofa_io.hpp"
#include "harness/support/errors.hpp"
#include "cli_support.hpp"
#include "test_scenario_files.hpp"
#include "../skip.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <set>
#include <unistd.h>

// libmysofa 1.3.1 itself leaks ~1 KiB of attribute strings when it rejects some malformed files
// (the optional outside corpus); that is the library's, not ours: keep LeakSanitizer (SONOMAP_SANITIZE) quiet
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

// Debian's default HRIR set: MIT KEMAR, normal pinna, 710 directions x 2 ears x 512 taps.
const fs::path kDebianSofa = "/usr/share/libmysofa/default.sofa";

// Where `what` occurs in `bytes`; fails the test unless it occurs exactly once (a mutation
// aimed at it must hit it and nothing else).
size_t only_place_of(const std::string& bytes, const std::string& what) {
  const size_t at = bytes.find(what);
  INFO("looking for '" << what << "'");
  REQUIRE(at != std::string::npos);
  REQUIRE(bytes.find(what, at + 1) == std::string::npos);
  return at;
}

std::string le64(uint64_t v) {
  std::string out(8, '\0');
  for (int i = 0; i < 8; ++i) out[i] = static_cast<char>(v >> (8 * i));
  return out;
}

// A copy of `bytes` with the bytes from `at` on replaced by `with`.
std::string patched(std::string bytes, size_t at, const std::string& with) {
  REQUIRE(at + with.size() <= bytes.size());
  bytes.replace(at, with.size(), with);
  return bytes;
}

// A copy with the last byte of the (only) occurrence of `text` changed.
std::string text_flipped(const std::string& bytes, const std::string& text) {
  const size_t at = only_place_of(bytes, text) + text.size() - 1;
  return patched(bytes, at, std::string(1, static_cast<char>(bytes[at] ^ 0x01)));
}

// Data.IR's dataspace holds its dimensions as little-endian 64-bit M, R, N, twice (current and
// maximum size); a copy with both copies of dimension `which` set to `value`.
std::string ir_dimension_set(const std::string& bytes, int which, uint64_t value) {
  const std::string dims = le64(710) + le64(2) + le64(512);
  const size_t current = bytes.find(dims);
  REQUIRE(current != std::string::npos);
  const size_t maximum = bytes.find(dims, current + 1);
  REQUIRE(maximum != std::string::npos);
  std::string out = patched(bytes, current + 8 * which, le64(value));
  return patched(out, maximum + 8 * which, le64(value));
}

struct Malformed {
  std::string name;
  std::string bytes;
};

// Files a reader must refuse, each a small, named change to a good file.
std::vector<Malformed> malformed_from(const std::string& good) {
  std::vector<Malformed> out{{"empty", ""}, {"text", "not a SOFA file, only its name\n"}};
  for (size_t length : {size_t{7}, size_t{64}, size_t{4096}, good.size() / 4, good.size() / 2,
                        good.size() - 1})
    out.push_back({"truncated to " + std::to_string(length) + " bytes", good.substr(0, length)});
  // HDF5 superblock (version 0): signature, then the root group's object header address at 64.
  out.push_back({"HDF5 signature changed", text_flipped(good, "\x89HDF")});
  REQUIRE(good.compare(64, 8, le64(good.find("OHDR"))) == 0);  // the first object header
  out.push_back({"root object header past the end", patched(good, 64, le64(good.size() + 1))});
  out.push_back({"end-of-file address 100", patched(good, 40, le64(100))});
  // Attributes and variable names libmysofa checks.
  out.push_back({"SOFAConventions not SimpleFreeFieldHRIR", text_flipped(good, "SimpleFreeFieldHRIR")});
  out.push_back({"DataType not FIR", text_flipped(good, "FIR")});
  out.push_back({"no Data.SamplingRate", text_flipped(good, "Data.SamplingRate")});
  out.push_back({"no Data.IR", text_flipped(good, "Data.IR")});
  // Data.IR's dimensions disagree with M, R, N or with the data stored.
  const int m = 0, r = 1, n = 2;
  out.push_back({"Data.IR with M = 0", ir_dimension_set(good, m, 0)});
  out.push_back({"Data.IR with R = 0", ir_dimension_set(good, r, 0)});
  out.push_back({"Data.IR with N = 0", ir_dimension_set(good, n, 0)});
  out.push_back({"Data.IR with M + 1", ir_dimension_set(good, m, 711)});
  out.push_back({"Data.IR with N + 1", ir_dimension_set(good, n, 513)});
  out.push_back({"Data.IR with 1 receiver", ir_dimension_set(good, r, 1)});
  out.push_back({"Data.IR with 3 receivers", ir_dimension_set(good, r, 3)});
  out.push_back({"Data.IR with M = 2^40", ir_dimension_set(good, m, uint64_t{1} << 40)});
  return out;
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
  CHECK(back.room_type == "shoebox");
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
  const audio::HrirSet kemar = read_hrir_set(kDebianSofa, 48000.0);
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

TEST_CASE("malformed SOFA files made from Debian's default.sofa are refused, naming the file",
          "[sofa]") {
  const std::string good = sonomap::test::text_of(kDebianSofa);
  REQUIRE(good.size() > 100000);
  const sonomap::test::ScratchDir scratch("sofa-malformed");
  for (const Malformed& bad : malformed_from(good)) {
    INFO(bad.name);
    const fs::path file = scratch.write("malformed.sofa", bad.bytes);
    const std::string message = sonomap::test::input_error_of([&] { read_sofa(file); });
    CHECK(message.find(file.string()) != std::string::npos);
  }
}

TEST_CASE("sonomap brir with a malformed --hrir file exits 2 and writes nothing", "[sofa][cli]") {
  const std::string good = sonomap::test::text_of(kDebianSofa);
  const sonomap::test::ScratchDir scratch("sofa-malformed-cli");
  // One of each kind (the reader test above takes them all): a process start costs most here.
  const std::set<std::string> kinds{"empty", "text", "truncated to 64 bytes",
                                    "HDF5 signature changed", "DataType not FIR", "no Data.IR",
                                    "Data.IR with M + 1"};
  int runs = 0;
  for (const Malformed& bad : malformed_from(good)) {
    if (!kinds.count(bad.name)) continue;
    ++runs;
    INFO(bad.name);
    const fs::path file = scratch.write("hrir.sofa", bad.bytes);
    const fs::path out = scratch.path() / "brirs";
    const auto result = sonomap::test::run_sonomap(
        {"--quiet", "brir", "--hrir", file.string(), "--out", out.string()});
    CHECK(result.status == 2);
    CHECK(result.output.find(file.string()) != std::string::npos);
    CHECK(sonomap::test::nothing_written(out));
  }
  CHECK(runs == static_cast<int>(kinds.size()));
}

TEST_CASE("bytes changed at random in default.sofa's metadata: a clean load or a clear error",
          "[sofa]") {
  // The metadata (superblock, object headers, attributes, B-trees) is in the first 20 kB; most
  // single-byte changes there are harmless, some break the file. Never a crash or a half load.
  const std::string good = sonomap::test::text_of(kDebianSofa);
  const sonomap::test::ScratchDir scratch("sofa-flips");
  std::mt19937_64 rng(2024);
  int refused = 0;
  for (int i = 0; i < 32; ++i) {
    std::string bytes = good;
    const size_t at = static_cast<size_t>(rng() % 20000);
    bytes[at] = static_cast<char>(bytes[at] ^ static_cast<char>(1 + rng() % 255));
    INFO("byte " << at);
    const fs::path file = scratch.write("flipped.sofa", bytes);
    try {
      const SofaContents s = read_sofa(file);
      CHECK(s.irs.size() == 710);  // a clean load is a whole one
    } catch (const InputError& e) {
      ++refused;
      CHECK(std::string(e.what()).find(file.string()) != std::string::npos);
    }
  }
  CHECK(refused > 0);
}

TEST_CASE("an outside corpus of malformed SOFA files, if present: a clear error or a clean load",
          "[sofa]") {
  // libmysofa's own fuzzing finds, kept beside the repository on the maintainers' machines
  // (cmake -DSONOMAP_SOFA_CORPUS=DIR); a fresh clone does not have them and skips.
  const fs::path bad_dir = SONOMAP_SOFA_CORPUS;
  if (bad_dir.empty() || !fs::is_directory(bad_dir)) {
    SONOMAP_SKIP("no corpus of malformed SOFA files at '" << bad_dir.string()
                 << "' (cmake -DSONOMAP_SOFA_CORPUS=DIR)");
  }
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
  CHECK(files > 0);
  CHECK(refused > 0);
}
