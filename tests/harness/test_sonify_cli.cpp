// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap sonify` and `sonomap brir` end to end: outputs on success; on bad input a clear
// message, exit status 2 and no WAV (not even a partial one).
#include "harness/formats/circle_io.hpp"
#include "harness/formats/sofa_io.hpp"
#include "harness/formats/wav_io.hpp"
#include "harness/support/errors.hpp"
#include "cli_support.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace sonomap;
using namespace sonomap::harness;

namespace {

struct Result {
  int status;
  std::string err;
};

Result run(const std::string& args, const fs::path& dir) {
  const char* exe = std::getenv("SONOMAP_EXE");
  REQUIRE(exe != nullptr);
  const fs::path err = dir / "stderr.txt";
  const std::string cmd = std::string(exe) + " " + args + " 2> " + err.string();
  const int raw = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream text;
  text << in.rdbuf();
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text.str()};
}

// Unit-impulse BRIRs on the paper's grid: tiny files, the output is the dry sweep.
void write_impulse_brirs(const fs::path& dir) {
  const auto grid = audio::BrirGrid::paper();
  std::vector<audio::BinauralIr> irs(grid.azimuths_deg.size() * grid.distances_m.size());
  for (auto& ir : irs) {
    ir.left.assign(16, 0.0f);
    ir.right.assign(16, 0.0f);
    ir.left[0] = ir.right[0] = 1.0f;
  }
  write_brir_directory(dir, audio::BrirSet(48000.0, grid, std::move(irs)));
}

std::string circle_text(int rows, const std::string& bin_17_range) {
  std::string s = "bin,range\n";
  for (int k = 0; k < rows; ++k)
    s += std::to_string(k) + "," + (k == 17 ? bin_17_range : (k % 3 == 0 ? "" : "1.5")) + "\n";
  return s;
}

bool only_inputs_left(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.find("sweep") != std::string::npos) return false;  // WAV, events or partial
  }
  return true;
}

}  // namespace

TEST_CASE("sonify writes a 48 kHz stereo sweep and its event log", "[cli][sonify]") {
  const sonomap::test::ScratchDir scratch("sonify-ok");
  const fs::path& dir = scratch.path();
  write_impulse_brirs(dir / "brirs");
  std::ofstream(dir / "circle.csv") << circle_text(360, "0.8");
  const Result r = run("-q sonify " + (dir / "circle.csv").string() + " --out " +
                           (dir / "sweep.wav").string() + " --brir " + (dir / "brirs").string(),
                       dir);
  INFO(r.err);
  REQUIRE(r.status == 0);
  const StereoAudio wav = read_wav(dir / "sweep.wav");
  CHECK(wav.sample_rate == 48000.0);
  CHECK(wav.left.size() >= 2 * 48000);  // one 2 s period at least
  std::ifstream events(dir / "sweep.events.csv");
  std::string line;
  int rows = 0;
  std::getline(events, line);
  CHECK(line.rfind("time_s,sector,azimuth_deg,range_m,brir_distance_m", 0) == 0);
  std::string first;
  while (std::getline(events, line)) rows += !line.empty(), first = first.empty() ? line : first;
  CHECK(rows == 36);
  // Sector 1 holds bin 17 at 0.8 m: the second event is that tap, 1/36 of a period later.
  std::ifstream again(dir / "sweep.events.csv");
  std::getline(again, line);
  std::getline(again, line);
  std::getline(again, line);
  CHECK(line.rfind("0.055556,1,17.500,0.8000,0.80,18.0,-4.0,tap", 0) == 0);
  fs::remove_all(dir);
}

TEST_CASE("sonify refuses bad circles and BRIR directories: exit 2, no WAV", "[cli][sonify]") {
  const sonomap::test::ScratchDir scratch("sonify-bad");
  const fs::path& dir = scratch.path();
  write_impulse_brirs(dir / "brirs");
  const std::string out = " --out " + (dir / "sweep.wav").string();
  const std::string brirs = " --brir " + (dir / "brirs").string();

  std::ofstream(dir / "short.csv") << circle_text(359, "1.0");
  Result r = run("-q sonify " + (dir / "short.csv").string() + out + brirs, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("short.csv") && Catch::Contains("359 bins, expected 360"));
  CHECK(only_inputs_left(dir));

  std::ofstream(dir / "nan.csv") << circle_text(360, "nan");
  r = run("-q sonify " + (dir / "nan.csv").string() + out + brirs, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("nan.csv:19") && Catch::Contains("range"));
  CHECK(only_inputs_left(dir));

  std::ofstream(dir / "good.csv") << circle_text(360, "1.0");
  fs::create_directories(dir / "empty");
  r = run("-q sonify " + (dir / "good.csv").string() + out + " --brir " + (dir / "empty").string(), dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("no .sofa files"));
  CHECK(only_inputs_left(dir));

  fs::remove(dir / "brirs" / brir_file_name(3.6));
  r = run("-q sonify " + (dir / "good.csv").string() + out + brirs, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("missing BRIRs for distance 3.6"));
  CHECK(only_inputs_left(dir));

  const auto grid = audio::BrirGrid::paper();
  std::vector<audio::BinauralIr> irs(grid.azimuths_deg.size(),
                                     {std::vector<float>(16, 0.0f), std::vector<float>(16, 0.0f)});
  write_brir_sofa(dir / "brirs" / brir_file_name(3.6), 44100.0, 3.6, grid.azimuths_deg, irs);
  r = run("-q sonify " + (dir / "good.csv").string() + out + brirs, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("sample rate 44100"));
  CHECK(only_inputs_left(dir));
  fs::remove_all(dir);
}

TEST_CASE("brir writes the paper's grid that sonify then loads, without --brir a room is "
          "synthesised in memory",
          "[cli][brir]") {
  const sonomap::test::ScratchDir scratch("sonify-brir");
  const fs::path& dir = scratch.path();
  Result r = run("-q brir --room 5x4x3 --rt60 0.2 --order 0 --ir-length 0.03 --out " +
                     (dir / "set").string(),
                 dir);
  INFO(r.err);
  REQUIRE(r.status == 0);
  const audio::BrirSet set = read_brir_directory(dir / "set", 48000.0);
  CHECK(set.azimuth_count() == 120);
  CHECK(set.distance_count() == 10);
  CHECK(set.grid().azimuths_deg.front() == Approx(-177.0));
  CHECK(set.ir_length() == 1440);

  r = run("-q brir --room 5x4x3 --listener 9,1,1 --out " + (dir / "bad").string(), dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("listener"));
  CHECK(!fs::exists(dir / "bad"));

  std::ofstream(dir / "circle.csv") << circle_text(360, "2.0");
  r = run("sonify " + (dir / "circle.csv").string() + " --out " + (dir / "sweep.wav").string() +
              " --rt60 0.2 --order 0 --ir-length 0.03 --mode objects",
          dir);
  CHECK(r.status == 0);
  CHECK_THAT(r.err, Catch::Contains("synthesising BRIRs"));
  CHECK(fs::exists(dir / "sweep.wav"));
  fs::remove_all(dir);
}


TEST_CASE("two renders of a sweep are byte-identical, WAV and events", "[cli][sonify]") {
  const sonomap::test::ScratchDir scratch("sonify-twice");
  const fs::path& dir = scratch.path();
  write_impulse_brirs(dir / "brirs");
  std::ofstream(dir / "circle.csv") << circle_text(360, "0.8");
  for (const char* name : {"a.wav", "b.wav"}) {
    const Result r = run("-q sonify " + (dir / "circle.csv").string() + " --out " +
                             (dir / name).string() + " --brir " + (dir / "brirs").string(),
                         dir);
    INFO(r.err);
    REQUIRE(r.status == 0);
    if (std::string(name) == "a.wav") sleep(1);  // a timestamp in the file would differ
  }
  using sonomap::test::text_of;
  CHECK(text_of(dir / "a.wav").size() > 44);
  CHECK(text_of(dir / "a.wav") == text_of(dir / "b.wav"));
  CHECK(text_of(dir / "a.events.csv") == text_of(dir / "b.events.csv"));
  CHECK(text_of(dir / "a.wav").find("PEAK") == std::string::npos);
}

TEST_CASE("absurd rooms and an IR shorter than the direct sound are refused: exit 2, nothing "
          "written",
          "[cli][brir]") {
  const sonomap::test::ScratchDir scratch("brir-bounds");
  const fs::path& dir = scratch.path();
  const std::string out = " --out " + (dir / "set").string();
  Result r = run("-q brir --room 1e300x4x3" + out, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("room"));
  r = run("-q brir --room 0.2x0.2x0.2" + out, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("room sides must be in [1, 500] m"));
  r = run("-q brir --room 5x4x3 --listener 0.1,2,1.5" + out, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("0.25 m from every wall"));
  r = run("-q brir --rt60 30" + out, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("rt60 must be in (0.01, 3] s"));
  // 4 m at 343 m/s is 11.7 ms before the HRIR even starts: 10 ms cannot hold it.
  r = run("-q brir --ir-length 0.01" + out, dir);
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Catch::Contains("--ir-length") && Catch::Contains("direct sound"));
  CHECK(!fs::exists(dir / "set"));
  std::ofstream(dir / "circle.csv") << circle_text(360, "1.0");
  r = run("-q sonify " + (dir / "circle.csv").string() + " --room 0.2x0.2x0.2 --out " +
              (dir / "sweep.wav").string(),
          dir);
  CHECK(r.status == 2);
  CHECK(!fs::exists(dir / "sweep.wav"));
}
