// SPDX-License-Identifier: GPL-3.0-or-later
// A moved object in the map: a 40 cm box stands 1.5 m in front of a wall 3 m ahead of a static
// camera, then vanishes (the scenario's disappear time). The circle's bins that pointed at the
// box must read the wall again: VDB-GPDF's free-space carving within carving_frame_bound
// frames; the TSDF peer only with space carving on (without it, rays that now end at the wall
// never update the box's old surface, so the box stays for good).
#include "core/rasteriser.hpp"
#include "core/tsdf.hpp"
#include "core/vdb_gpdf.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <utility>

using namespace sonomap;
using sonomap::test::Box;
using sonomap::test::Scene;

namespace {

const Box kWall{Eigen::Vector3d(3.0, -2.5, 0.0), Eigen::Vector3d(3.2, 2.5, 2.0)};
const Box kObject{Eigen::Vector3d(1.3, -0.2, 0.6), Eigen::Vector3d(1.7, 0.2, 1.0)};
const Eigen::Vector3d kEye(0.0, 0.0, 0.8);
constexpr int kFramesWithBox = 60;  // long enough to saturate a weight cap of 30

struct BoxBins {
  int on_box = 0;   // bins within 5 cm of the box's front face (1.3 m / cos azimuth)
  int on_wall = 0;  // bins within 5 cm of the wall (3 m / cos azimuth)
};

// The circle's bins within 7 degrees of straight ahead (the box is 2 atan(0.2 / 1.3) = 17.5
// degrees wide), read from the map's surface.
BoxBins box_bins(const Mapper& map) {
  RasterConfig config;
  config.band_min = 0.5;  // the band holds the box (0.6-1.0 m) and the wall, not the open floor
  config.band_max = 1.1;
  Rasteriser rasteriser(config);
  RasterOrigin origin;
  origin.position = kEye;
  std::vector<Eigen::Vector3f> samples;
  map.surface_points(kEye, 5.0, samples);
  rasteriser.reset(origin);
  rasteriser.add(samples);
  BoxBins out;
  for (int bin = 0; bin < rasteriser.circle().size(); ++bin) {
    const double az = rasteriser.circle().bin_centre_deg(bin);
    if (!(az < 7.0 || az > 353.0)) continue;
    const double c = std::cos(az * M_PI / 180.0);
    const float range = rasteriser.circle().bins[bin].range;
    if (std::abs(range - 1.3 / c) < 0.05) ++out.on_box;
    if (std::abs(range - 3.0 / c) < 0.05) ++out.on_wall;
  }
  return out;
}

// Integrates the box scene, then the scene without it; returns the bins before the box went
// and the number of frames until every box bin reads the wall (-1: not within max_frames).
std::pair<BoxBins, int> frames_to_clear(Mapper& map, int max_frames) {
  const Scene with_box{{kWall, kObject}, {}};
  const Scene without_box{{kWall}, {}};
  const Eigen::Isometry3d camera = test::look_at(kEye, kEye + Eigen::Vector3d::UnitX());
  for (int i = 0; i < kFramesWithBox; ++i) map.integrate(test::render(with_box, camera, i));
  const BoxBins before = box_bins(map);
  for (int k = 1; k <= max_frames; ++k) {
    map.integrate(test::render(without_box, camera, kFramesWithBox + k));
    const BoxBins now = box_bins(map);
    if (now.on_box == 0 && now.on_wall >= before.on_box) return {before, k};
  }
  return {before, -1};
}

}  // namespace

TEST_CASE("VDB-GPDF: a removed box's bins return to the wall behind it within the carving bound",
          "[vdb_gpdf][dynamic]") {
  VdbGpdf map;
  // Bound: the deepest fused value behind the front face is trunc_behind query steps; every
  // frame carves it with at least the distance from the box's back to the wall (1.3 m).
  const auto& c = map.config();
  const double bound = carving_frame_bound(c.weight_cap, c.trunc_behind * c.query_step, 1.3);
  REQUIRE(std::isfinite(bound));
  const auto [before, frames] = frames_to_clear(map, 100);
  INFO("box bins " << before.on_box << ", frames to clear " << frames << ", bound " << bound);
  REQUIRE(before.on_box >= 12);
  CHECK(before.on_wall == 0);
  CHECK(frames >= 1);
  CHECK(frames <= bound);
}

TEST_CASE("TSDF peer: a removed box is cleared with space carving and stays without it",
          "[tsdf][dynamic]") {
  Tsdf with_carving;  // the default
  REQUIRE(with_carving.config().space_carving);
  const auto [before, frames] = frames_to_clear(with_carving, 100);
  INFO("with carving: box bins " << before.on_box << ", frames to clear " << frames);
  REQUIRE(before.on_box >= 12);
  CHECK(frames >= 1);
  CHECK(frames <= 40);  // a weight cap of 30: the old value keeps at most 30/31 per frame

  TsdfConfig plain;
  plain.space_carving = false;  // VDBFusion's default
  Tsdf without_carving(plain);
  const auto [before_plain, frames_plain] = frames_to_clear(without_carving, 100);
  INFO("without carving: box bins " << before_plain.on_box << ", frames to clear " << frames_plain);
  REQUIRE(before_plain.on_box >= 12);
  CHECK(frames_plain == -1);  // still there after 100 frames: a ghost for good
}
