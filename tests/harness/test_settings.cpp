// SPDX-License-Identifier: GPL-3.0-or-later
// One declaration per setting: every number a user gives is bounded (one test per bound class),
// a scenario's errors come all at once, the mapper settings `--set` lists are the ones
// summary.json records, and the key reference in docs/ is the one the tables print.
#include "cli_support.hpp"
#include "run_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/app/cli.hpp"
#include "harness/formats/run_summary.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/formats/tum_io.hpp"

#include <nlohmann/json.hpp>

#include <sstream>

namespace fs = std::filesystem;
using sonomap::harness::load_scenario;
using sonomap::test::input_error_of;
using sonomap::test::run_sonomap;
using sonomap::test::kBase;
using sonomap::test::ScratchDir;
using sonomap::test::with_line;

namespace {

// The error of loading `text`: it names the file, the line and the key.
void check_refused(const std::string& text, int line, const std::string& key) {
  ScratchDir dir("settings");
  const fs::path file = dir.write("probe.yaml", text);
  const std::string message = input_error_of([&] { load_scenario(file); });
  INFO(message);
  CHECK(message.find(file.string() + ":" + std::to_string(line) + ":") != std::string::npos);
  CHECK(message.find("'" + key + "'") != std::string::npos);
}

sonomap::sim::Scenario accepted(const std::string& text) {
  ScratchDir dir("settings");
  return load_scenario(dir.write("ok.yaml", text));
}

// kBase with `text` after its line 6 (the sensor's max_range): sensor keys at line 7.
std::string with_sensor_line(const std::string& text) { return with_line(6, "  max_range: 5.0\n" + text); }

// The names after "(settings: " in a message, up to the closing parenthesis.
std::vector<std::string> listed_settings(const std::string& message) {
  const auto start = message.find("(settings: ");
  REQUIRE(start != std::string::npos);
  std::istringstream list(message.substr(start + 11, message.find(')', start) - start - 11));
  std::vector<std::string> names;
  for (std::string name; std::getline(list, name, ',');) names.push_back(name.substr(name[0] == ' '));
  return names;
}

}  // namespace

TEST_CASE("intrinsics: fx = 1e300 is refused naming sensor.intrinsics.fx and its line",
          "[settings][bounds]") {
  check_refused(with_line(4, "  intrinsics: {fx: 1e300, fy: 525, cx: 319.5, cy: 239.5}"), 4,
                "sensor.intrinsics.fx");
  check_refused(with_line(4, "  intrinsics: {fx: 525, fy: 0.5, cx: 319.5, cy: 239.5}"), 4,
                "sensor.intrinsics.fy");
}

TEST_CASE("ranges: a camera range of 1e300 m is refused (ranges reach at most 100 m)",
          "[settings][bounds]") {
  check_refused(with_line(6, "  max_range: 1e300"), 6, "sensor.max_range");
  check_refused(with_line(6, "  max_range: 100.5"), 6, "sensor.max_range");
  CHECK(accepted(with_line(6, "  max_range: 100")).camera.max_range == 100.0);
}

TEST_CASE("rates: a frame rate above 1 kHz is refused", "[settings][bounds]") {
  check_refused(with_sensor_line("  rate: 1e300"), 7, "sensor.rate");
  CHECK(accepted(with_sensor_line("  rate: 1000")).camera.rate_hz == 1000.0);
}

TEST_CASE("positions: keyframe and mounting positions beyond 10 km are refused",
          "[settings][bounds]") {
  check_refused(with_line(10, "    - {time: 0, position: [1e300, 0, 1.5], yaw: 0}"), 10,
                "body.keyframes[0].position[0]");
  check_refused(with_sensor_line("  mounting: {position: [0, 0, 1e300]}"), 7,
                "sensor.mounting.position[2]");
  check_refused(with_line(14, "    room: {size: [4, 4, 2.5]}\n    pose: {position: [10001, 0, 0]}"),
                15, "static[0].pose.position[0]");
}

TEST_CASE("seeds: -1 and 2^63 are refused, 2^63-1 is the largest seed", "[settings][bounds]") {
  check_refused(with_line(1, "seed: -1"), 1, "seed");
  check_refused(with_line(1, "seed: 9223372036854775808"), 1, "seed");
  CHECK(accepted(with_line(1, "seed: 9223372036854775807")).seed == 9223372036854775807ull);
}

TEST_CASE("mesh vertices: a vertex at 1e30 m is refused naming the mesh file key",
          "[settings][bounds]") {
  ScratchDir dir("settings");
  dir.write("far.obj", "v 0 0 0\nv 1 0 0\nv 0 1e30 0\nf 1 2 3\n");
  const fs::path file = dir.write("probe.yaml", kBase + "  - name: far\n    mesh: {file: far.obj}\n");
  const std::string message = input_error_of([&] { load_scenario(file); });
  INFO(message);
  CHECK(message.find("static[1].mesh.file") != std::string::npos);
  CHECK(message.find("vertex 2") != std::string::npos);
}

TEST_CASE("a scenario with three bad keys reports all three, each with its line",
          "[settings][scenario]") {
  std::string text = with_line(1, "seed: -1");
  text.replace(text.find("fx: 525"), 7, "fx: 1e300");
  text.replace(text.find("  min_range: 0.3"), 16, "  rat: 30");
  ScratchDir dir("settings");
  const fs::path file = dir.write("probe.yaml", text);
  const std::string message = input_error_of([&] { load_scenario(file); });
  INFO(message);
  CHECK(message.find("3 problems") != std::string::npos);
  for (const auto& [line, key] : std::vector<std::pair<int, std::string>>{
           {1, "seed"}, {4, "sensor.intrinsics.fx"}, {5, "sensor.rat"}})
    CHECK(message.find(file.string() + ":" + std::to_string(line) + ": key '" + key + "'") !=
          std::string::npos);
}

TEST_CASE("at most 20 errors of a scenario are listed, and the count of the rest",
          "[settings][scenario]") {
  std::string text = kBase + "  - name: boxes\n    box: {size: [1, 1, 1]}\n";
  for (int i = 0; i < 25; ++i) text += "    bad" + std::to_string(i) + ": 1\n";
  ScratchDir dir("settings");
  const std::string message = input_error_of([&] { load_scenario(dir.write("probe.yaml", text)); });
  INFO(message);
  CHECK(message.find("25 problems") != std::string::npos);
  CHECK(message.find("bad19") != std::string::npos);
  CHECK(message.find("bad20") == std::string::npos);
  CHECK(message.find("(5 more not shown)") != std::string::npos);
}

TEST_CASE("TUM sequences with unsorted or repeated timestamps are refused at the first offender",
          "[settings][bounds][tum]") {
  ScratchDir dir("settings");
  dir.write("seq/camera.yaml", "width: 4\nheight: 4\nintrinsics: {fx: 4, fy: 4, cx: 2, cy: 2}\n");
  const std::string pose = " 0 0 0 0 0 0 1\n";
  SECTION("ground truth out of order") {
    dir.write("seq/groundtruth.txt", "# poses\n1.0" + pose + "2.0" + pose + "1.5" + pose);
    dir.write("seq/depth.txt", "1.0 d/1.png\n");
    const std::string message =
        input_error_of([&] { sonomap::harness::read_tum_sequence(dir.path() / "seq"); });
    INFO(message);
    CHECK(message.find("groundtruth.txt:4:") != std::string::npos);
  }
  SECTION("a repeated depth timestamp") {
    dir.write("seq/groundtruth.txt", "1.0" + pose + "2.0" + pose);
    dir.write("seq/depth.txt", "1.0 d/1.png\n2.0 d/2.png\n2.0 d/3.png\n");
    const std::string message =
        input_error_of([&] { sonomap::harness::read_tum_sequence(dir.path() / "seq"); });
    INFO(message);
    CHECK(message.find("depth.txt:3:") != std::string::npos);
  }
}

TEST_CASE("command line numbers: --voxel 0, a keyframe at 1e300 and --near-below > --far-above exit 2",
          "[settings][bounds][cli]") {
  ScratchDir scratch("settings-cli");
  const fs::path out = scratch.path() / "out";
  const std::string scenario = sonomap::test::shipped("scenes/smoke.yaml").string();
  const auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"--quiet", "run", scenario, "--out", out.string(), "--frames", "2"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_sonomap(args);
  };
  for (const auto& extra : std::vector<std::vector<std::string>>{
           {"--voxel", "0"},
           {"--voxel", "1e-6"},
           {"--set", "mapper.global_voxel=0"},
           {"--set", "body.keyframes.0.position=[1e300, 0, 1.5]"},
           {"--set", "sensor.mounting={position: [1e300, 0, 0]}"},
           {"--set", "raster.max_range=1e300"},
           {"--seed", "-1"}}) {
    const auto r = run(extra);
    INFO(extra[0] << " " << extra[1] << ": " << r.output);
    CHECK(r.status == 2);
  }
  CHECK(sonomap::test::nothing_written(out));

  std::string circle = "bin,range\n";
  for (int bin = 0; bin < 360; ++bin) circle += std::to_string(bin) + ",2\n";
  const fs::path csv = scratch.write("circle.csv", circle);
  const auto sonify = run_sonomap({"--quiet", "sonify", csv.string(), "--out", (scratch.path() / "s.wav").string(),
                                   "--near-below", "3", "--far-above", "2"});
  INFO(sonify.output);
  CHECK(sonify.status == 2);
  CHECK(sonify.output.find("--near-below") != std::string::npos);
}

// Whether `text` says "about <number> GiB" (digits, '.', 'e' or '+'). Not std::regex: GCC 12
// warns of uninitialised members inside its regex compiler under -fsanitize (a false alarm).
namespace {
bool states_gib_estimate(const std::string& text) {
  for (size_t at = text.find("about "); at != std::string::npos; at = text.find("about ", at + 1)) {
    const size_t number = at + 6;
    const size_t end = text.find_first_not_of("0123456789.e+", number);
    if (end != number && end != std::string::npos && text.compare(end, 4, " GiB") == 0) return true;
  }
  return false;
}
}  // namespace

TEST_CASE("a voxel whose map would exceed --max-memory is refused before any work, with the estimate",
          "[settings][bounds][cli]") {
  ScratchDir scratch("settings-memory");
  const fs::path out = scratch.path() / "out";
  const auto r = run_sonomap({"--quiet", "run", sonomap::test::shipped("scenes/smoke.yaml").string(),
                              "--out", out.string(), "--voxel", "0.001", "--max-memory", "1"});
  INFO(r.output);
  CHECK(r.status == 2);
  CHECK(states_gib_estimate(r.output));
  CHECK(r.output.find("--max-memory") != std::string::npos);
  CHECK(sonomap::test::nothing_written(out));
}

TEST_CASE("set mapper.nope: the run lists the mapper's fields, and summary.json records every one of them",
          "[settings][summary]") {
  ScratchDir scratch("settings-summary");
  const std::string scenario = sonomap::test::shipped("scenes/smoke.yaml").string();
  for (const std::string mapper : {"vdb_gpdf", "tsdf"}) {
    const fs::path out = scratch.path() / mapper;
    const auto nope = run_sonomap({"--quiet", "run", scenario, "--out", out.string(), "--mapper", mapper,
                                   "--set", "mapper.nope=1"});
    REQUIRE(nope.status == 2);
    const std::vector<std::string> fields = listed_settings(nope.output);
    CHECK(fields.size() >= 7);

    // A value set on the command line comes back as summary.json's value.
    auto o = sonomap::test::smoke_run(out, mapper, 1);
    o.overrides.push_back("mapper.max_range=4.25");
    o.overrides.push_back("edf.enabled=false");
    o.write_rasters = false;
    const nlohmann::json summary = sonomap::harness::run_scenario(o).summary;
    const nlohmann::json config = summary["config"]["mapper_config"];
    for (const std::string& field : fields) {
      INFO(mapper << ": " << field);
      CHECK(config.contains(field));
    }
    CHECK(config["max_range"] == "4.25");
  }
}

TEST_CASE("docs/settings.md holds the key reference the tables print", "[settings][docs]") {
  const std::string doc = sonomap::test::text_of(sonomap::test::shipped("docs/settings.md"));
  const std::string generated = sonomap::harness::key_reference_markdown();
  INFO("regenerate: sonomap keys, between the markers in docs/settings.md");
  CHECK(doc.find(generated) != std::string::npos);
}

TEST_CASE("run --help gives every run key and mapper setting with its default",
          "[settings][help]") {
  const auto help = run_sonomap({"run", "--help"});
  CHECK(help.status == 0);
  for (const std::string line : {"raster.max_range = 5 ", "edf.every = 5 ", "metrics.edge_jump = 0.25 ",
                                 "mapper.query_radius = 2 ", "mapper.truncation = 0.15 ",
                                 "--every INT:INT in [1 - 10000000]=1", "--max-memory"}) {
    INFO(line);
    CHECK(help.output.find(line) != std::string::npos);
  }
}
