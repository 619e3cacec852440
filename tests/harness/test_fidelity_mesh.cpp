// SPDX-License-Identifier: GPL-3.0-or-later
// The circle never reads farther than the map's own mesh. The circle is built the run loop's
// way (the map's cached surface samples through the rasteriser); the mesh the map exports is
// rasterised by the exact wedge clipper of eval/ground_truth (no sampling, no shared code with
// the rasteriser or the surface cache). In a small room of boxes (corner, low box, thin panel,
// table top on legs), seen by a walking, turning head with a mixed-pixel camera, every bin
// where the mesh has surface must read it to within half a voxel, for VDB-GPDF and the TSDF
// peer.
#include "core/rasteriser.hpp"
#include "core/tsdf.hpp"
#include "core/vdb_gpdf.hpp"
#include "eval/ground_truth.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

using namespace sonomap;
using sonomap::test::Box;
using sonomap::test::Scene;

namespace {

Scene small_room() {
  Scene s;
  auto box = [&](double x0, double y0, double z0, double x1, double y1, double z1) {
    s.boxes.push_back({Eigen::Vector3d(x0, y0, z0), Eigen::Vector3d(x1, y1, z1)});
  };
  box(-4, -4, -0.1, 4, 4, 0.0);        // floor
  box(3.0, -3, 0, 3.2, 3, 2.5);        // wall ahead
  box(-3, 2.4, 0, 3, 2.6, 2.5);        // wall to the left
  box(1.6, -0.9, 0, 2.1, -0.4, 1.2);   // box with a corner toward the head
  box(1.4, 0.5, 0, 1.9, 1.0, 0.35);    // low box
  box(2.2, 0.1, 0.45, 2.24, 0.7, 1.2); // raised thin panel, a chair's back
  box(0.8, 1.3, 0.71, 1.6, 1.9, 0.75); // table top
  for (double x : {0.85, 1.55})
    for (double y : {1.35, 1.85}) box(x - 0.025, y - 0.025, 0, x + 0.025, y + 0.025, 0.71);
  return s;
}

std::vector<eval::GroundTruthTriangle> mesh_triangles(const Mapper& map) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  map.surface_mesh(vertices, triangles);
  std::vector<eval::GroundTruthTriangle> out;
  out.reserve(triangles.size());
  for (const auto& t : triangles)
    out.push_back({vertices[t[0]].cast<double>(), vertices[t[1]].cast<double>(), vertices[t[2]].cast<double>()});
  return out;
}

// Bins where the map's mesh has surface in the band and the circle reads it more than `tol`
// farther (or not at all), over frames 4, 8, ... of a 16-frame walk.
int bins_farther_than_mesh(Mapper& map, double tol, int* compared) {
  const Scene scene = small_room();
  const RasterConfig config;
  Rasteriser rasteriser(config);
  int farther = 0;
  for (int i = 0; i < 16; ++i) {
    const double f = i / 15.0, heading = (-30.0 + 60.0 * f) * M_PI / 180.0;
    const Eigen::Vector3d eye(-0.5 + 0.8 * f, 0.2 * f, 1.5);
    const Eigen::Vector3d ahead(std::cos(heading), std::sin(heading), -std::tan(15.0 * M_PI / 180.0));
    map.integrate(test::render(scene, test::look_at(eye, eye + ahead), i, 200, 150, 5.0, true));
    if (i % 4 != 3) continue;
    RasterOrigin origin;
    origin.position = eye;
    origin.heading = heading;
    std::vector<Eigen::Vector3f> samples;
    map.surface_points(eye, config.max_range, samples);
    rasteriser.reset(origin);
    rasteriser.add(samples);
    const eval::GroundTruthRasters mesh = eval::ground_truth_rasters(mesh_triangles(map), origin, config);
    for (int b = 0; b < config.azimuth_bins; ++b) {
      const RasterCell& m = mesh.circle.bins[b];
      if (!m.known()) continue;
      ++*compared;
      const RasterCell& c = rasteriser.circle().bins[b];
      if (!c.known() || c.range > m.range + tol) {
        ++farther;
        UNSCOPED_INFO("frame " << i << " bin " << b << ": mesh " << m.range << " m, circle "
                               << (c.known() ? c.range : -1.0f) << " m");
      }
    }
  }
  return farther;
}

}  // namespace

TEST_CASE("Fidelity: in no bin does the circle read farther than the map's own mesh (half a voxel)",
          "[fidelity]") {
  SECTION("vdb_gpdf") {
    VdbGpdf map;
    int compared = 0;
    CHECK(bins_farther_than_mesh(map, 0.5 * map.config().global_voxel, &compared) == 0);
    CHECK(compared > 300);  // the mesh had surface in that many bins: not vacuous
  }
  SECTION("tsdf") {
    Tsdf map;
    int compared = 0;
    CHECK(bins_farther_than_mesh(map, 0.5 * map.config().voxel, &compared) == 0);
    CHECK(compared > 300);  // the mesh had surface in that many bins: not vacuous
  }
}
