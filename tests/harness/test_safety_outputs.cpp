// SPDX-License-Identifier: GPL-3.0-or-later
// Users' data is sacred: --out never replaces what sonomap did not write, and an output is
// never an input. Each refusal is exit status 2 with nothing touched.
#include "test_safety_support.hpp"

#include "harness/support/output.hpp"

#include <map>
#include <sys/stat.h>

namespace fs = std::filesystem;
using namespace sonomap::test;

namespace {

const fs::path kSmoke = smoke_scene();

// A circle CSV as `sonify` reads it: every bin 2 m away.
std::string circle_csv() {
  std::string text = "bin,range\n";
  for (int k = 0; k < 360; ++k) text += std::to_string(k) + ",2.0\n";
  return text;
}

// Every file under `dir` with its contents, to show nothing changed.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file()) files[entry.path().string()] = text_of(entry.path());
  return files;
}

}  // namespace

TEST_CASE("run --out a folder holding a user's file exits 2 and the file is still there",
          "[safety]") {
  ScratchDir scratch("safety-user-dir");
  const fs::path notes = scratch.write("mine/notes.txt", "my thesis notes\n");
  const auto result = run_sonomap(short_run(kSmoke, scratch.path() / "mine"));
  INFO(result.output);
  CHECK(result.status == 2);
  CHECK(result.output.find("exists and is not a sonomap result; choose another --out") !=
        std::string::npos);
  CHECK(text_of(notes) == "my thesis notes\n");
  CHECK(partial_entries(scratch.path()).empty());
}

TEST_CASE("run --out an existing file exits 2 and the file is unchanged", "[safety]") {
  ScratchDir scratch("safety-user-file");
  const fs::path file = scratch.write("results.txt", "precious\n");
  const auto result = run_sonomap(short_run(kSmoke, file));
  INFO(result.output);
  CHECK(result.status == 2);
  CHECK(text_of(file) == "precious\n");
}

TEST_CASE("run --out the scenario, its folder or its mesh folder exits 2 naming both paths",
          "[safety]") {
  ScratchDir scratch("safety-scenario-dir");
  const fs::path scenario = scratch.write("scenes/smoke.yaml", text_of(kSmoke));
  const fs::path mesh = scratch.write("scenes/meshes/person.ply",
                                      text_of(shipped("scenes/meshes/person.ply")));
  const fs::path link = scratch.path() / "link";  // a symbolic link to the scenario's folder
  fs::create_directory_symlink(scenario.parent_path(), link);
  const auto before = snapshot(scratch.path());
  const std::vector<std::pair<fs::path, fs::path>> cases{
      {scenario.parent_path(), scenario}, {scenario, scenario},
      {link, scenario}, {mesh.parent_path(), mesh},
      {mesh.parent_path() / "new", mesh}};  // `new` would lie beside, not inside: allowed below
  for (std::size_t i = 0; i + 1 < cases.size(); ++i) {
    const auto& [out, input] = cases[i];
    const auto result = run_sonomap(short_run(scenario, out));
    INFO(result.output);
    CHECK(result.status == 2);
    CHECK(result.output.find("output " + out.string()) != std::string::npos);
    CHECK(result.output.find("the input " + input.string()) != std::string::npos);
  }
  CHECK(snapshot(scratch.path()) == before);
  // A new folder beside the inputs is fine: nothing of theirs is in it.
  CHECK(run_sonomap(short_run(scenario, cases.back().first)).status == 0);
  CHECK(text_of(mesh) == text_of(shipped("scenes/meshes/person.ply")));
}

TEST_CASE("run --out equal to or inside the input sequence exits 2 and the sequence is intact",
          "[safety]") {
  ScratchDir scratch("safety-sequence");
  const fs::path seq = scratch.path() / "seq";
  std::vector<std::string> render{"--quiet", "render", kSmoke.string(), "--out", seq.string(),
                                  "--frames", "2"};
  for (const std::string& o : small_camera()) render.insert(render.end(), {"--set", o});
  REQUIRE(run_sonomap(render).status == 0);
  const auto before = snapshot(seq);
  for (const fs::path& out : {seq, seq / "result", seq / "depth"}) {
    std::vector<std::string> args{"--quiet", "run", seq.string(), "--out", out.string(),
                                  "--pictures", "-1", "--sweeps", "-1"};
    const auto result = run_sonomap(args);
    INFO(result.output);
    CHECK(result.status == 2);
    CHECK(result.output.find("the input " + seq.string()) != std::string::npos);
  }
  CHECK(snapshot(seq) == before);
}

TEST_CASE("sonify --out its own input exits 2 and the circle is unchanged", "[safety]") {
  ScratchDir scratch("safety-sonify");
  const fs::path circle = scratch.write("circle.csv", circle_csv());
  const auto result = run_sonomap({"--quiet", "sonify", circle.string(), "--out", circle.string()});
  INFO(result.output);
  CHECK(result.status == 2);
  CHECK(result.output.find("is the input") != std::string::npos);
  CHECK(text_of(circle) == circle_csv());
}

TEST_CASE("sonify replaces a sweep it wrote but not a user's WAV of the same name", "[safety]") {
  ScratchDir scratch("safety-sonify-wav");
  const fs::path circle = scratch.write("circle.csv", circle_csv());
  const fs::path users = scratch.write("song.wav", "RIFF not ours");
  auto result = run_sonomap({"--quiet", "sonify", circle.string(), "--out", users.string()});
  CHECK(result.status == 2);
  CHECK(text_of(users) == "RIFF not ours");
  CHECK(!fs::exists(scratch.path() / "song.events.csv"));

  const fs::path wav = scratch.path() / "sweep.wav";
  REQUIRE(run_sonomap({"--quiet", "sonify", circle.string(), "--out", wav.string()}).status == 0);
  struct stat before {};
  REQUIRE(::stat(wav.c_str(), &before) == 0);
  const std::string events = text_of(scratch.path() / "sweep.events.csv");
  result = run_sonomap({"--quiet", "sonify", circle.string(), "--out", wav.string()});
  INFO(result.output);
  CHECK(result.status == 0);
  struct stat after {};
  REQUIRE(::stat(wav.c_str(), &after) == 0);
  CHECK(after.st_ino != before.st_ino);  // a new file renamed into place
  CHECK(after.st_size == before.st_size);
  CHECK(text_of(scratch.path() / "sweep.events.csv") == events);  // of the same circle
}

TEST_CASE("render, brir, compare and bench refuse a user's folder or file with exit 2",
          "[safety]") {
  ScratchDir scratch("safety-commands");
  const fs::path notes = scratch.write("mine/notes.txt", "keep\n");
  const fs::path mine = notes.parent_path();
  const fs::path json = scratch.write("bench.json", "{\"mine\": true}\n");
  const fs::path sweep = scratch.write("sweep.yaml", "name: s\nscenarios:\n  - {id: smoke, file: " +
                                                        kSmoke.string() + "}\nvariants:\n  - {id: depth, mapper: depth_only}\n");
  const std::vector<std::vector<std::string>> commands{
      {"render", kSmoke.string(), "--out", mine.string()},
      {"brir", "--out", mine.string()},
      {"compare", sweep.string(), "--out", mine.string()},
      {"report", mine.string()},
      {"bench", "map", kSmoke.string(), "--json", json.string()}};
  for (const auto& command : commands) {
    const auto result = run_sonomap(command);
    INFO(command[0] << ": " << result.output);
    CHECK(result.status == 2);
    const bool refused = result.output.find("not a sonomap result") != std::string::npos ||
                         result.output.find("not written by sonomap") != std::string::npos;
    CHECK(refused);
  }
  CHECK(text_of(notes) == "keep\n");
  CHECK(text_of(json) == "{\"mine\": true}\n");
  CHECK(std::distance(fs::directory_iterator(mine), fs::directory_iterator()) == 1);
}

TEST_CASE("a rerun into a previous result replaces it whole", "[safety]") {
  ScratchDir scratch("safety-rerun");
  const fs::path out = scratch.path() / "out";
  REQUIRE(run_sonomap(short_run(kSmoke, out, 3)).status == 0);
  CHECK(sonomap::harness::is_sonomap_result(out));
  CHECK(text_of(out / ".sonomap-result").rfind("sonomap run ", 0) == 0);
  const auto result = run_sonomap(short_run(kSmoke, out, 5));
  INFO(result.output);
  REQUIRE(result.status == 0);
  const std::string summary = text_of(out / "summary.json");
  CHECK(summary.find("\"frames\": 5") != std::string::npos);
  CHECK(partial_entries(scratch.path()).empty());
  CHECK(std::distance(fs::directory_iterator(scratch.path()), fs::directory_iterator()) == 1);
}
