// SPDX-License-Identifier: GPL-3.0-or-later
// compare: every combination of a sweep file is an independent run; the report rolls up what
// exists; a rerun skips finished runs; the job list is one command per run.
#include "cli_support.hpp"
#include "score_support.hpp"
#include "test_scenario_files.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <csignal>
#include <sstream>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace fs = std::filesystem;

namespace {

int line_count(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

std::string tiny_sweep() {
  return "name: tiny\n"
         "frames: 3\n"
         "set: [sensor.width=160, sensor.height=120, sensor.intrinsics.fx=131.25,\n"
         "      sensor.intrinsics.fy=131.25, sensor.intrinsics.cx=79.5, sensor.intrinsics.cy=59.5]\n"
         "scenarios:\n"
         "  - {id: smoke, file: " + sonomap::test::shipped("scenes/smoke.yaml").string() + "}\n"
         "variants:\n"
         "  - {id: depth, mapper: depth_only}\n"
         "  - {id: tsdf10, mapper: tsdf, voxel: 0.1}\n"
         "pictures: [-1]\n"
         "sweeps: [-1]\n";
}

}  // namespace

TEST_CASE("a sweep runs each variant once, rolls them up, and a rerun skips finished runs",
          "[compare]") {
  sonomap::test::ScratchDir scratch("compare");
  const fs::path sweep = scratch.write("sweep.yaml", tiny_sweep());
  const fs::path out = scratch.path() / "out";

  const auto jobs = sonomap::test::run_sonomap({"compare", sweep.string(), "--out", out.string(), "--emit-jobs"});
  REQUIRE(jobs.status == 0);
  CHECK(line_count(jobs.output) == 2);
  CHECK(!fs::exists(out / "runs"));  // emitting jobs runs nothing

  const auto first = sonomap::test::run_sonomap({"compare", sweep.string(), "--out", out.string(), "-j", "2"});
  INFO(first.output);
  REQUIRE(first.status == 0);
  CHECK(fs::exists(out / "runs" / "smoke-depth-s1" / "summary.json"));
  CHECK(fs::exists(out / "runs" / "smoke-tsdf10-s1" / "summary.json"));
  CHECK(line_count(sonomap::test::text_of(out / "rollup.csv")) == 1 + 2);
  CHECK(sonomap::test::text_of(out / "report.md").find("smoke-tsdf10-s1") != std::string::npos);

  const auto second = sonomap::test::run_sonomap({"compare", sweep.string(), "--out", out.string()});
  CHECK(second.status == 0);
  CHECK(second.output.find("2 finished before, 0 to run") != std::string::npos);
}

TEST_CASE("a sweep file with an unknown key is rejected with its line", "[compare]") {
  sonomap::test::ScratchDir scratch("compare-bad");
  const fs::path sweep = scratch.write("sweep.yaml", tiny_sweep() + "varaints: []\n");
  const auto r = sonomap::test::run_sonomap({"compare", sweep.string(), "--out", (scratch.path() / "out").string()});
  CHECK(r.status == 2);
  CHECK(r.output.find("sweep.yaml:12") != std::string::npos);
  CHECK(r.output.find("varaints") != std::string::npos);
  CHECK(!fs::exists(scratch.path() / "out"));
}

// The paper's figures as claims: a camera with a 57 degree field of view cannot see the whole
// circle, and sees well under half of it, whatever the code does; a claim on a column the
// roll-up does not have is "not measured", never a verdict.
TEST_CASE("a sweep's claims are checked against the roll-up: agrees, differs, not measured",
          "[compare][claims]") {
  sonomap::test::ScratchDir scratch("compare-claims");
  const std::string claims =
      "claims:\n"
      "  - {text: a camera sees under half the circle, scenario: smoke, variant: depth,\n"
      "     metric: circle_final_coverage, op: '<', value: 0.5, paper: below 20%}\n"
      "  - {text: a camera sees the whole circle, scenario: smoke, variant: depth,\n"
      "     metric: circle_final_coverage, op: '>=', value: 0.99}\n"
      "  - {text: no such figure, scenario: smoke, variant: depth, metric: no_such_column,\n"
      "     op: '>', value: 0}\n";
  const fs::path sweep = scratch.write("sweep.yaml", tiny_sweep() + claims);
  const fs::path out = scratch.path() / "out";
  const auto r = sonomap::test::run_sonomap({"compare", sweep.string(), "--out", out.string(), "-j", "2"});
  INFO(r.output);
  REQUIRE(r.status == 0);
  const std::string report = sonomap::test::text_of(out / "report.md");
  INFO(report);
  CHECK(report.find("## Against the paper") != std::string::npos);
  CHECK(report.find("| a camera sees under half the circle") != std::string::npos);
  CHECK(report.find("1 agree, 1 differ, 1 not measured.") != std::string::npos);

  // `report` alone rebuilds the same section from the directory.
  fs::remove(out / "report.md");
  REQUIRE(sonomap::test::run_sonomap({"report", out.string()}).status == 0);
  CHECK(sonomap::test::text_of(out / "report.md") == report);
}

TEST_CASE("a claim naming a variant the sweep does not have is rejected with its line and key",
          "[compare][claims]") {
  sonomap::test::ScratchDir scratch("compare-claims-bad");
  const fs::path sweep = scratch.write(
      "sweep.yaml", tiny_sweep() +
                        "claims:\n"
                        "  - {text: t, scenario: smoke, variant: depth, metric: circle_final_coverage,\n"
                        "     op: '<', value: 1, versus: gpdf}\n");
  const auto r = sonomap::test::run_sonomap({"compare", sweep.string(), "--out", (scratch.path() / "out").string()});
  CHECK(r.status == 2);
  CHECK(r.output.find("sweep.yaml:14") != std::string::npos);  // the line of `versus`
  CHECK(r.output.find("claims[0].versus") != std::string::npos);
  CHECK(!fs::exists(scratch.path() / "out"));
}

// Ctrl-C during a sweep: the sweep stops with status 130, the runs that finished stay, the one
// that was running leaves no partial directory, and a rerun runs only what is missing.
TEST_CASE("an interrupted sweep keeps its finished runs, leaves no partial one, and resumes",
          "[compare][interrupt]") {
  const char* exe = std::getenv("SONOMAP_EXE");
  REQUIRE(exe);
  sonomap::test::ScratchDir scratch("compare-interrupt");
  const std::string sweep_text =
      "name: long\n"
      "frames: 150\n"
      "set: [sensor.width=160, sensor.height=120, sensor.intrinsics.fx=131.25,\n"
      "      sensor.intrinsics.fy=131.25, sensor.intrinsics.cx=79.5, sensor.intrinsics.cy=59.5]\n"
      "scenarios:\n"
      "  - {id: room, file: " + sonomap::test::shipped("scenes/room.yaml").string() + "}\n"
      "variants:\n"
      "  - {id: a, mapper: vdb_gpdf, voxel: 0.1}\n"
      "  - {id: b, mapper: vdb_gpdf, voxel: 0.15}\n"
      "  - {id: c, mapper: vdb_gpdf, voxel: 0.2}\n"
      "  - {id: d, mapper: vdb_gpdf, voxel: 0.25}\n"
      "pictures: [-1]\n"
      "sweeps: [-1]\n";
  const fs::path sweep = scratch.write("sweep.yaml", sweep_text);
  const fs::path out = scratch.path() / "out";
  std::vector<std::string> args{exe, "--quiet", "compare", sweep.string(), "--out", out.string()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  REQUIRE(posix_spawn(&pid, exe, nullptr, nullptr, argv.data(), environ) == 0);

  // Interrupt as soon as the first run has finished (its directory appears whole).
  auto finished = [&] {
    int n = 0;
    if (fs::exists(out / "runs"))
      for (const auto& e : fs::directory_iterator(out / "runs"))
        if (fs::exists(e.path() / "summary.json")) ++n;
    return n;
  };
  for (int waited_ms = 0; finished() == 0 && waited_ms < 300000; waited_ms += 20) usleep(20000);
  REQUIRE(finished() >= 1);
  ::kill(pid, SIGINT);
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  const int kept = finished();
  INFO("finished runs when interrupted: " << kept);
  REQUIRE(kept < 4);  // the sweep had not finished, so the interrupt was tested
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  for (const auto& e : fs::directory_iterator(out / "runs")) {
    INFO(e.path());
    CHECK(fs::exists(e.path() / "summary.json"));  // no partial directory left behind
  }

  const auto resumed = sonomap::test::run_sonomap({"compare", sweep.string(), "--out", out.string(), "-j", "2"});
  CHECK(resumed.status == 0);
  CHECK(resumed.output.find(std::to_string(kept) + " finished before, " + std::to_string(4 - kept) +
                            " to run") != std::string::npos);
  CHECK(finished() == 4);
}

// An external mapper as a sweep variant: a python3 program with only the standard library that
// reads the rendered sequence's frame list and writes a constant-range circle for its last
// frame. It is scored beside a built-in mapper; a failing and a timed-out command fail their
// own runs only. Its RMSE is the closed-form one of a constant circle in the square room.
TEST_CASE("a sweep variant may be an external command, scored beside the built-in mappers",
          "[compare][score]") {
  if (sonomap::harness::run_program({"python3", "-c", "pass"}) != 0) {
    WARN("skipped: python3 is not installed (an external mapper needs it)");
    return;
  }
  sonomap::test::ScratchDir scratch("compare-command");
  scratch.write("square.yaml", sonomap::test::square_room_scenario());
  const fs::path mapper = scratch.write(
      "my_mapper.py",
      "import os, sys\n"
      "sequence, out, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])\n"
      "stamps = [l for l in open(os.path.join(sequence, 'depth.txt')) if not l.startswith('#')]\n"
      "assert len(stamps) == frames, (len(stamps), frames)\n"
      "with open(os.path.join(out, 'circle.csv'), 'w') as f:\n"
      "    f.write('frame,bin,estimate\\n')\n"
      "    for b in range(360):\n"
      "        f.write('%d,%d,%s\\n' % (frames - 1, b, sys.argv[4]))\n");
  const std::string sweep_text =
      "name: external\nseeds: [1]\nset: [edf.enabled=false]\n"
      "scenarios:\n  - {id: square, file: square.yaml}\n"
      "variants:\n"
      "  - {id: depth, mapper: depth_only}\n"
      "  - {id: mine, command: \"python3 '" + mapper.string() + "' {sequence} {out} {frames} 1.5\"}\n"
      "  - {id: broken, command: \"python3 -c 'import sys; sys.exit(3)'\"}\n"
      "  - {id: slow, command: \"python3 -c 'import time; time.sleep(30)'\", timeout: 0.5}\n"
      "pictures: [-1]\nsweeps: [-1]\n";
  const fs::path sweep = scratch.write("sweep.yaml", sweep_text);
  const fs::path out = scratch.path() / "out";
  const auto r = sonomap::test::run_sonomap({"--quiet", "compare", sweep.string(), "--out", out.string(), "-j", "2"});
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(r.output.find("run failed: square-broken-s1") != std::string::npos);
  CHECK(r.output.find("run failed: square-slow-s1") != std::string::npos);
  CHECK(sonomap::test::text_of(out / "logs" / "square-broken-s1.log").find("exited with status 3") != std::string::npos);
  CHECK(sonomap::test::text_of(out / "logs" / "square-slow-s1.log").find("timed out after 0.5 s") != std::string::npos);
  REQUIRE(fs::exists(out / "runs" / "square-mine-s1" / "summary.json"));
  CHECK(fs::exists(out / "runs" / "square-depth-s1" / "summary.json"));
  CHECK(!fs::exists(out / "runs" / "square-broken-s1"));
  const auto summary = nlohmann::json::parse(sonomap::test::text_of(out / "runs" / "square-mine-s1" / "summary.json"));
  CHECK(summary["metrics"]["circle"]["final"]["rmse"].get<double>() ==
        Approx(sonomap::test::square_room_rmse(1.5)).epsilon(1e-6));
  const std::string rollup = sonomap::test::text_of(out / "rollup.csv");
  CHECK(rollup.find("square-mine-s1,square,mine,mine,") != std::string::npos);
  CHECK(rollup.find("square-depth-s1,square,depth,depth_only,") != std::string::npos);
  // The sequence was rendered once, into the cache.
  int sequences = 0;
  for (const auto& e : fs::directory_iterator(out / "sequences")) sequences += e.is_directory();
  CHECK(sequences == 1);
}

// The shipped sweeps are where users start their own A/B from (the Cow and Lady sweep's name once
// held a '-', which names refuse). Each lists its runs, and each runs Open3D's
// ScalableTSDFVolume, the reference people know, beside VDB-GPDF.
TEST_CASE("every shipped sweep lists its runs, Open3D's beside VDB-GPDF's", "[compare]") {
  sonomap::test::ScratchDir scratch("compare-shipped");
  for (const std::string name : {"paper", "dynamic_ab", "cow_and_lady_paper"}) {
    const auto jobs = sonomap::test::run_sonomap({"compare", sonomap::test::shipped("scenes/" + name + ".yaml").string(),
                                                  "--out", (scratch.path() / name).string(), "--emit-jobs"});
    INFO(name << ": " << jobs.output);
    REQUIRE(jobs.status == 0);
    CHECK(jobs.output.find("--mapper vdb_gpdf") != std::string::npos);
    CHECK(jobs.output.find("--mapper open3d") != std::string::npos);
  }
}
