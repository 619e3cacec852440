// SPDX-License-Identifier: GPL-3.0-or-later
// The shipped smoke scene, whole and at full resolution: VDB-GPDF's circle against its peers'
// on the same frames, each against the exact truth the run writes beside it (circle.csv).
#include "test_scenario_files.hpp"

#include "harness/app/run.hpp"
#include "harness/report/rollup.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using sonomap::test::ScratchDir;

namespace {

// A circle.csv cell: empty is unknown (nothing within range), read as infinitely far.
double range_cell(const std::string& cell) { return cell.empty() ? INFINITY : std::stod(cell); }

// Bin-frames of circle.csv whose estimate and truth differ by more than 0.1 m, or where one of
// them is unknown and the other is not.
int bins_off(const fs::path& circle_csv) {
  std::ifstream in(circle_csv);
  std::string line;
  std::getline(in, line);
  const auto header = sonomap::harness::RollupTable::parse(line);
  const int estimate = header.column("estimate"), truth = header.column("truth");
  REQUIRE(estimate >= 0);
  REQUIRE(truth >= 0);
  int off = 0, rows = 0;
  while (std::getline(in, line)) {
    const auto cells = sonomap::harness::split_csv_line(line);
    const double e = range_cell(cells[estimate]), t = range_cell(cells[truth]);
    ++rows;
    if (std::isinf(e) && std::isinf(t)) continue;
    if (std::isinf(e) || std::isinf(t) || std::abs(e - t) > 0.1) ++off;
  }
  CHECK(rows == 60 * 360);
  return off;
}

int smoke_bins_off(const fs::path& out, const std::string& mapper) {
  sonomap::harness::RunOptions o;
  o.scenario = sonomap::test::shipped("scenes/smoke.yaml");
  o.out = out;
  o.mapper = mapper;
  o.overrides = {"edf.enabled=false"};
  o.picture_frames = {-1};
  o.sweep_frames = {-1};
  o.quiet = true;
  sonomap::harness::run_scenario(o);
  return bins_off(out / "circle.csv");
}

}  // namespace

TEST_CASE("Fidelity: on the whole smoke scene VDB-GPDF's circle is off in no more bin-frames than "
          "Open3D's or the TSDF peer's",
          "[fidelity][shipped]") {
  // 60 frames, every frame's 360 bins. Measured on main 5752e71 (before VDB-GPDF gave the
  // space beside silhouettes a value): VDB-GPDF 16,763, Open3D and the TSDF peer 16,749 each
  // (most bins are off for all three: the walls outside the view, which no map has seen).
  ScratchDir scratch("shipped-smoke");
  const int vdb = smoke_bins_off(scratch.path() / "vdb_gpdf", "vdb_gpdf");
  const int open3d = smoke_bins_off(scratch.path() / "open3d", "open3d");
  const int tsdf = smoke_bins_off(scratch.path() / "tsdf", "tsdf");
  INFO("bin-frames off by more than 0.1 m: vdb_gpdf " << vdb << ", open3d " << open3d << ", tsdf " << tsdf);
  CHECK(vdb <= open3d);
  CHECK(vdb <= tsdf);
}
