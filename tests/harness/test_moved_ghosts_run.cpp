// SPDX-License-Identifier: GPL-3.0-or-later
// Ghost clearing as `run` reports it, on scenes/large_object_leaves.yaml: a 0.7 x 0.9 x 1.7 m
// cabinet 1.35 m ahead of a still listener jumps 1.5 m aside between frames 30 and 31, and from
// frame 31 the camera sees the wall 3 m ahead through its old place. The figures in
// summary.json are checked against a recount from circle.csv and frames.csv with the cabinet's
// footprint as the scene file gives it (no eval code), and against what the report prints.
#include "run_support.hpp"
#include "test_scenario_files.hpp"

#include "harness/app/run.hpp"
#include "harness/formats/run_summary.hpp"
#include "harness/report/report.hpp"
#include "harness/report/rollup.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace fs = std::filesystem;
using sonomap::test::ScratchDir;

namespace {

constexpr int kFrames = 60;
constexpr int kSeenEmpty = 31;  // the first frame without the cabinet in its old place
// The cabinet's old footprint (scenes/large_object_leaves.yaml: centre (-0.8, 0), 0.7 x 0.9 m).
constexpr double kX0 = -1.15, kX1 = -0.45, kY0 = -0.45, kY1 = 0.45;

sonomap::harness::RunOptions cabinet_run(const fs::path& out, const std::string& mapper) {
  sonomap::harness::RunOptions o;
  o.scenario = sonomap::test::shipped("scenes/large_object_leaves.yaml");
  o.out = out;
  o.mapper = mapper;
  o.frames = kFrames;
  o.overrides = sonomap::test::small_camera();
  o.picture_frames = {-1};
  o.sweep_frames = {-1};
  o.quiet = true;
  return o;
}

double cell_number(const std::string& s) { return s.empty() ? NAN : std::stod(s); }

// Per frame, the bins whose estimate lies in the cabinet's old footprint grown by `grow` (the
// point at the bin's centre azimuth from the listener's true pose, which is the raster's:
// the scene has exact localisation) and is a ghost: nearer than the truth by more than `tol`
// or where the truth is empty.
std::map<int, int> recount(const fs::path& dir, double tol, double grow) {
  std::map<int, std::array<double, 3>> pose;  // x, y, heading (rad)
  {
    std::ifstream in(dir / "frames.csv");
    std::string line;
    std::getline(in, line);
    const auto header = sonomap::harness::RollupTable::parse(line);
    const int f = header.column("frame"), x = header.column("x"), y = header.column("y"),
              h = header.column("heading_deg");
    while (std::getline(in, line)) {
      const auto c = sonomap::harness::split_csv_line(line);
      pose[std::stoi(c[f])] = {std::stod(c[x]), std::stod(c[y]), std::stod(c[h]) * M_PI / 180.0};
    }
  }
  std::map<int, int> count;
  std::ifstream in(dir / "circle.csv");
  std::string line;
  std::getline(in, line);  // frame,bin,estimate,truth
  while (std::getline(in, line)) {
    const auto c = sonomap::harness::split_csv_line(line);
    const int frame = std::stoi(c[0]), bin = std::stoi(c[1]);
    count.try_emplace(frame, 0);
    const double estimate = cell_number(c[2]), truth = cell_number(c[3]);
    if (std::isnan(estimate) || !(std::isnan(truth) || truth - estimate > tol)) continue;
    const auto& [px, py, heading] = pose.at(frame);
    const double a = heading + (bin + 0.5) * M_PI / 180.0;
    const double x = px + estimate * std::cos(a), y = py + estimate * std::sin(a);
    if (x >= kX0 - grow && x <= kX1 + grow && y >= kY0 - grow && y <= kY1 + grow) ++count[frame];
  }
  return count;
}

std::map<int, int> frames_column(const fs::path& dir, const std::string& name) {
  std::ifstream in(dir / "frames.csv");
  std::string line;
  std::getline(in, line);
  const auto header = sonomap::harness::RollupTable::parse(line);
  const int f = header.column("frame"), c = header.column(name);
  REQUIRE(c >= 0);
  std::map<int, int> out;
  while (std::getline(in, line)) {
    const auto cells = sonomap::harness::split_csv_line(line);
    out[std::stoi(cells[f])] = std::stoi(cells[c]);
  }
  return out;
}

// The last frame at or after kSeenEmpty with a bin counted, or -1.
int last_counted(const std::map<int, int>& count) {
  int last = -1;
  for (const auto& [frame, n] : count)
    if (frame >= kSeenEmpty && n > 0) last = frame;
  return last;
}

// The summary's figures agree with the recount. The run places estimate points in cells of
// half the tolerance, and circle.csv gives a bin's range but not the azimuth inside its degree
// (1.2 cm at this range): the recount's footprint grown by the tolerance less / plus those
// margins brackets the run's count.
void check_against_recount(const fs::path& dir, const sonomap::eval::MovedObjectClearing& m, double tol) {
  const double margin = 0.5 * std::max(0.5 * tol, 0.02) + 0.015;
  const auto strict = recount(dir, tol, tol - margin), loose = recount(dir, tol, tol + margin);
  const auto reported = frames_column(dir, "circle_moved_ghosts");
  for (const auto& [frame, n] : reported) {
    INFO("frame " << frame);
    if (frame < kSeenEmpty) {
      CHECK(n == 0);  // the cabinet stands in its place: nothing of it is a ghost
      continue;
    }
    CHECK(strict.at(frame) <= n);
    CHECK(n <= loose.at(frame));
  }
  CHECK(m.seen_empty_frame == kSeenEmpty);
  const int final_frame = kFrames - 1;
  CHECK(strict.at(final_frame) <= m.ghost_bins_at_end + m.unseen_ghost_bins_at_end);
  CHECK(m.ghost_bins_at_end + m.unseen_ghost_bins_at_end <= loose.at(final_frame));
  if (m.cleared()) {
    // Cleared at the frame after the last one with a ghost in the old place.
    CHECK(last_counted(strict) + 1 - kSeenEmpty <= *m.clearing_frames);
    CHECK(*m.clearing_frames <= std::max(0, last_counted(loose) + 1 - kSeenEmpty));
  } else {
    CHECK(loose.at(final_frame) > 0);
  }
}

// The run rolled up alone: report.md's moved-objects row for the cabinet and rollup.csv.
std::pair<std::string, sonomap::harness::RollupTable> report_of(const fs::path& run, const fs::path& dir) {
  fs::create_directories(dir / "runs");
  fs::copy(run, dir / "runs" / run.filename(), fs::copy_options::recursive);
  sonomap::harness::build_report(dir, true);
  std::ifstream md(dir / "report.md");
  std::string row;
  for (std::string line; std::getline(md, line);)
    if (line.find("| cabinet |") != std::string::npos) row = line;
  std::ifstream csv(dir / "rollup.csv");
  std::stringstream text;
  text << csv.rdbuf();
  return {row, sonomap::harness::RollupTable::parse(text.str())};
}

}  // namespace

TEST_CASE("ghost clearing: VDB-GPDF clears a cabinet that leaves within 10 frames of its old "
          "place being seen empty, and summary.json and the report say so",
          "[run][moved_ghosts]") {
  ScratchDir scratch("moved-vdb");
  const auto outcome = sonomap::harness::run_scenario(cabinet_run(scratch.path() / "vdb", "vdb_gpdf"));
  const sonomap::harness::RunSummary summary = sonomap::harness::read_run_summary(outcome.dir);
  REQUIRE(summary.moved_objects.size() == 1);
  const auto& m = summary.moved_objects[0];
  CHECK(m.name == "cabinet");
  check_against_recount(outcome.dir, m, summary.config.metrics.ghost_tolerance);
  REQUIRE(m.cleared());
  CHECK(*m.clearing_frames <= 10);
  CHECK(m.ghost_bins_at_end == 0);

  const auto [row, rollup] = report_of(outcome.dir, scratch.path() / "report");
  CHECK(row.find("| cabinet | 31 | " + std::to_string(*m.clearing_frames) + " |") != std::string::npos);
  REQUIRE(rollup.rows.size() == 1);
  CHECK(rollup.number(rollup.rows[0], rollup.column("moved_ghosts_clearing_frames")) == *m.clearing_frames);
  CHECK(rollup.number(rollup.rows[0], rollup.column("moved_ghosts_uncleared")) == 0);
}

TEST_CASE("ghost clearing: a TSDF without space carving never clears the cabinet, and the run "
          "reports it as never cleared with the ghost bins left",
          "[run][moved_ghosts]") {
  // Without carving, rays that now end at the wall never update the cabinet's old surface.
  ScratchDir scratch("moved-tsdf");
  auto options = cabinet_run(scratch.path() / "tsdf", "tsdf");
  options.overrides.push_back("mapper.carving=false");
  const auto outcome = sonomap::harness::run_scenario(options);
  const sonomap::harness::RunSummary summary = sonomap::harness::read_run_summary(outcome.dir);
  REQUIRE(summary.moved_objects.size() == 1);
  const auto& m = summary.moved_objects[0];
  check_against_recount(outcome.dir, m, summary.config.metrics.ghost_tolerance);
  CHECK_FALSE(m.cleared());
  CHECK_FALSE(m.clearing_frames.has_value());
  // The cabinet's front face covers 2 atan(0.45 / 1.35) = 37 degrees: most of those bins stay.
  CHECK(m.ghost_bins_at_end >= 20);
  CHECK(m.ghost_frames == kFrames - kSeenEmpty);
  const std::string screen = sonomap::harness::summary_screen(outcome);
  CHECK(screen.find("cabinet: ghosts never cleared, " + std::to_string(m.ghost_bins_at_end) + " bins left") !=
        std::string::npos);

  const auto [row, rollup] = report_of(outcome.dir, scratch.path() / "report");
  CHECK(row.find("| cabinet | 31 | never | " + std::to_string(m.ghost_bins_at_end) + " / ") != std::string::npos);
  REQUIRE(rollup.rows.size() == 1);
  CHECK(std::isnan(rollup.number(rollup.rows[0], rollup.column("moved_ghosts_clearing_frames"))));
  CHECK(rollup.number(rollup.rows[0], rollup.column("moved_ghosts_at_end")) == m.ghost_bins_at_end);
  CHECK(rollup.number(rollup.rows[0], rollup.column("moved_ghosts_uncleared")) == 1);
}
