// SPDX-License-Identifier: GPL-3.0-or-later
// The randomised fidelity suite: seeded random box rooms (plain, low, thin and raised panels,
// table tops on legs, and a large box that jumps away), a head that walks and turns through
// them looking 15 degrees down with a mixed-pixel camera (tests/core/test_vdb_gpdf_scene.hpp,
// closed-form ray casts), and every map's circle against the exact ground truth of the boxes'
// triangles (harness/ground_truth, which shares no code with the maps or the rasteriser).
// Per obstacle class, the bins off by more than 0.1 m are counted, and among them those read
// too far or not at all (misses: what a wearer walks into). VDB-GPDF must not miss more than
// the TSDF peer or Open3D in any class in view, nor read more bins too near in the classes
// where it matches them today (docs/fidelity.md). The table is printed (WARN) for docs/fidelity.md:
//   build/tests/test_harness "[fidelity]"
// Other rooms than the twelve the tests hold, to see whether a change holds beyond them:
//   SONOMAP_FIDELITY_SEEDS=13-40 build/tests/test_harness "[fidelity]"
#include "core/open3d_tsdf.hpp"
#include "core/rasteriser.hpp"
#include "core/tsdf.hpp"
#include "core/vdb_gpdf.hpp"
#include "eval/ground_truth.hpp"
#include "sim/cloud_frame.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iomanip>
#include <memory>
#include <sstream>

using namespace sonomap;
using sonomap::test::Box;
using sonomap::test::Scene;

namespace {

constexpr double kOff = 0.1;          // m
constexpr double kHead = 1.5;         // m
constexpr double kPitchDeg = 15.0;
// Seeds 1 .. kRooms, unless SONOMAP_FIDELITY_SEEDS says otherwise. Four rooms were too few: a
// class's count moved by one or two bins with any change, and rooms 5-12 overturned three of the
// verdicts the first four gave (docs/fidelity.md, "Twelve rooms"). The rings' suite runs 24
// (about 30 s): rings meet each surface a few times only, and rooms 13-24 showed misses at thin
// slabs and grazing faces that rooms 1-12 barely did (docs/fidelity.md, "A ring's own scan
// plane"). The images' suite runs 40 (about a minute): in twelve rooms VDB-GPDF read 3 bins too
// near at low boxes against the peers' 2, in forty 53 against 56, and rooms 25-36 alone read
// one grazing bin more too near than the TSDF peer (docs/fidelity.md, "Forty rooms").
constexpr int kRooms = 12;
constexpr int kImageRooms = 40;
constexpr int kRingRooms = 24;
constexpr int kFrames = 24;
constexpr int kMoveFrame = 12;        // the large box jumps away before this frame
constexpr int kWidth = 240, kHeight = 180;
constexpr double kFocal = 0.82 * kWidth;  // pixels (tests/core/test_vdb_gpdf_scene.hpp)
// One pixel's angle. A box that enters a bin by less than this (a corner 0.3 mm past the
// bin's edge at 2 m) is below what the camera resolves, and a map with the edge exactly
// right still misses that bin while one whose edge bulges 8 cm past the box reads it. A bin
// counts as read too far only when its obstacle is there even with the bin's edges moved by
// one pixel's angle to either side; the strict count (no tolerance) is printed beside it.
constexpr double kPixelAngle = 1.0 / kFocal;  // rad

enum Class { kCorner, kLow, kThin, kGrazing, kOutOfView, kVacated, kAll, kClassCount };
const std::array<const char*, kClassCount> kClassNames = {
    "corner (in view)", "low, top < 0.6 m (in view)", "thin or slab (in view)",
    "grazing > 60 deg (in view)", "out of view", "vacated by the moved box (in view)", "all bins"};

// Uniform in [lo, hi) from (seed, index): splitmix bits, no library distribution.
double uniform(uint64_t seed, uint64_t index, double lo, double hi) {
  const double u = static_cast<double>(test::mix_bits(seed * 1000003ull + index) >> 11) * 0x1.0p-53;
  return lo + (hi - lo) * u;
}

struct Obstacle {
  Box box;
  bool wall = false;
};

struct Room {
  std::vector<Obstacle> obstacles;  // walls and furniture, static
  Box mover_before, mover_after;    // the large box, before and after its jump
  double heading0_deg = 0.0;

  std::vector<Obstacle> at(int frame) const {
    std::vector<Obstacle> out = obstacles;
    out.push_back({frame < kMoveFrame ? mover_before : mover_after});
    return out;
  }
};

Box footprint_box(double cx, double cy, double sx, double sy, double z0, double z1) {
  return {Eigen::Vector3d(cx - 0.5 * sx, cy - 0.5 * sy, z0), Eigen::Vector3d(cx + 0.5 * sx, cy + 0.5 * sy, z1)};
}

// Walls of a 7 x 7 m room and eight pieces of furniture around the walk, in view of some frame.
Room random_room(uint64_t seed) {
  Room room;
  room.heading0_deg = uniform(seed, 0, 0.0, 360.0);
  for (const auto& [lo, hi] : {std::pair{Eigen::Vector3d(-3.8, -3.8, 0), Eigen::Vector3d(3.8, -3.5, 2.5)},
                               std::pair{Eigen::Vector3d(-3.8, 3.5, 0), Eigen::Vector3d(3.8, 3.8, 2.5)},
                               std::pair{Eigen::Vector3d(-3.8, -3.5, 0), Eigen::Vector3d(-3.5, 3.5, 2.5)},
                               std::pair{Eigen::Vector3d(3.5, -3.5, 0), Eigen::Vector3d(3.8, 3.5, 2.5)}})
    room.obstacles.push_back({{lo, hi}, true});
  uint64_t k = 1;
  auto place = [&](double& cx, double& cy) {
    const double a = (room.heading0_deg + uniform(seed, k++, -20.0, 80.0)) * M_PI / 180.0;
    const double r = uniform(seed, k++, 1.7, 3.0);
    cx = r * std::cos(a);
    cy = r * std::sin(a);
  };
  for (int i = 0; i < 8; ++i) {
    double cx, cy;
    place(cx, cy);
    const double sx = uniform(seed, k++, 0.3, 0.9), sy = uniform(seed, k++, 0.3, 0.9);
    switch (i % 4) {
      case 0:  // plain furniture
        room.obstacles.push_back({footprint_box(cx, cy, sx, sy, 0.0, uniform(seed, k++, 0.8, 1.8))});
        break;
      case 1:  // low
        room.obstacles.push_back({footprint_box(cx, cy, sx, sy, 0.0, uniform(seed, k++, 0.15, 0.55))});
        break;
      case 2: {  // thin panel, standing or raised like a chair's back
        const double t = uniform(seed, k++, 0.03, 0.06), base = uniform(seed, k++, 0.0, 1.0) < 0.5 ? 0.0 : 0.45;
        const bool along_x = uniform(seed, k++, 0.0, 1.0) < 0.5;
        room.obstacles.push_back({footprint_box(cx, cy, along_x ? sx + 0.3 : t, along_x ? t : sy + 0.3, base,
                                                base + uniform(seed, k++, 0.5, 1.0))});
        break;
      }
      default: {  // table top, 4 cm, on four 5 cm legs
        const double top = uniform(seed, k++, 0.6, 0.8);
        room.obstacles.push_back({footprint_box(cx, cy, sx + 0.4, sy + 0.3, top - 0.04, top)});
        for (double fx : {-1.0, 1.0})
          for (double fy : {-1.0, 1.0})
            room.obstacles.push_back({footprint_box(cx + fx * (0.5 * (sx + 0.4) - 0.05),
                                                    cy + fy * (0.5 * (sy + 0.3) - 0.05), 0.05, 0.05, 0.0, top - 0.04)});
      }
    }
  }
  double cx, cy;
  place(cx, cy);
  room.mover_before = footprint_box(cx, cy, 0.9, 0.7, 0.0, 1.7);
  // 1.5 m sideways (across the line of sight), staying in the room.
  const double n = std::hypot(cx, cy);
  room.mover_after = footprint_box(cx - 1.5 * cy / n, cy + 1.5 * cx / n, 0.9, 0.7, 0.0, 1.7);
  return room;
}

Scene scene_of(const std::vector<Obstacle>& obstacles) {
  Scene s;
  s.boxes.push_back({Eigen::Vector3d(-4, -4, -0.1), Eigen::Vector3d(4, 4, 0.0)});  // floor
  for (const auto& o : obstacles) s.boxes.push_back(o.box);
  return s;
}

// The head walks 1 m across the middle while turning 60 degrees.
Eigen::Isometry3d head_pose(const Room& room, int frame, double* heading_deg) {
  const double f = static_cast<double>(frame) / (kFrames - 1);
  const double h = (room.heading0_deg + 60.0 * f) * M_PI / 180.0;
  *heading_deg = h * 180.0 / M_PI;
  const Eigen::Vector3d eye(-0.5 + f, -0.3 + 0.6 * f, kHead);
  const Eigen::Vector3d ahead(std::cos(h), std::sin(h), -std::tan(kPitchDeg * M_PI / 180.0));
  return test::look_at(eye, eye + ahead);
}

std::vector<eval::GroundTruthTriangle> triangles_of(const std::vector<Box>& boxes) {
  std::vector<eval::GroundTruthTriangle> out;
  for (const Box& b : boxes) {
    auto corner = [&](int i) {
      return Eigen::Vector3d(i & 1 ? b.hi.x() : b.lo.x(), i & 2 ? b.hi.y() : b.lo.y(), i & 4 ? b.hi.z() : b.lo.z());
    };
    for (const auto& q : std::array<std::array<int, 4>, 6>{{{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                            {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}}}) {
      out.push_back({corner(q[0]), corner(q[1]), corner(q[2])});
      out.push_back({corner(q[0]), corner(q[2]), corner(q[3])});
    }
  }
  return out;
}

bool inside(const Box& b, const Eigen::Vector3d& p, double eps = 1e-3) {
  return (p.array() >= b.lo.array() - eps).all() && (p.array() <= b.hi.array() + eps).all();
}

// The classes of one bin whose exact nearest point is p (on obstacle o) seen from the camera.
std::array<bool, kClassCount> classify(const Obstacle& o, const Eigen::Vector3d& p, const Scene& scene,
                                       const Eigen::Isometry3d& camera) {
  std::array<bool, kClassCount> c{};
  c[kAll] = true;
  const Eigen::Vector3d eye = camera.translation();
  const Eigen::Vector3d pc = camera.inverse() * p;
  const bool in_image = pc.z() > 0.0 && std::abs(pc.x() / pc.z()) * kFocal <= 0.5 * kWidth &&
                        std::abs(pc.y() / pc.z()) * kFocal <= 0.5 * kHeight;
  const bool visible = in_image && scene.cast(eye, (p - eye).normalized()) >= (p - eye).norm() - 0.03;
  if (!visible) {
    c[kOutOfView] = true;
    return c;
  }
  if (o.wall) return c;
  const Box& b = o.box;
  const double corner_dx = std::min(std::abs(p.x() - b.lo.x()), std::abs(p.x() - b.hi.x()));
  const double corner_dy = std::min(std::abs(p.y() - b.lo.y()), std::abs(p.y() - b.hi.y()));
  c[kCorner] = std::hypot(corner_dx, corner_dy) < 0.1;
  c[kLow] = b.hi.z() < 0.6;
  c[kThin] = std::min(b.hi.x() - b.lo.x(), b.hi.y() - b.lo.y()) < 0.1 || b.hi.z() - b.lo.z() < 0.1;
  // Incidence on the vertical face the point lies on (the horizontal line of sight).
  const Eigen::Vector2d sight = (p - eye).head<2>().normalized();
  if (corner_dx < 1e-3) c[kGrazing] = c[kGrazing] || std::abs(sight.x()) < std::cos(60.0 * M_PI / 180.0);
  if (corner_dy < 1e-3) c[kGrazing] = c[kGrazing] || std::abs(sight.y()) < std::cos(60.0 * M_PI / 180.0);
  return c;
}

struct Tally {
  // far: read too far or not at all (one pixel's tolerance); strict_far: without it; near:
  // read nearer than the truth by over 0.1 m even with the bin turned a pixel either way (a
  // map's surface running past a silhouette; checked in the classes where VDB-GPDF matches its
  // peers, docs/fidelity.md)
  std::array<int, kClassCount> bins{}, off{}, far{}, strict_far{}, near{};
};

// The truths a map can be held to in each bin, from the bin's exact truth (`exact`) and the
// truths with the bins turned one pixel's angle either way: the farthest of them (infinite
// where one has no obstacle at all) for readings too far, the nearest for readings too near.
struct ResolvableTruth {
  std::vector<double> farthest, nearest;
};
ResolvableTruth resolvable_truth(const std::vector<eval::GroundTruthTriangle>& triangles, const Circle& exact,
                                 const RasterOrigin& origin, const RasterConfig& config) {
  auto range = [](const RasterCell& t) { return t.known() ? static_cast<double>(t.range) : HUGE_VAL; };
  ResolvableTruth out;
  for (int b = 0; b < config.azimuth_bins; ++b) out.farthest.push_back(range(exact.bins[b]));
  out.nearest = out.farthest;
  for (double turn : {-kPixelAngle, kPixelAngle}) {
    RasterOrigin turned = origin;
    turned.heading += turn;
    const auto truth = eval::ground_truth_rasters(triangles, turned, config);
    for (int b = 0; b < config.azimuth_bins; ++b) {
      out.farthest[b] = std::max(out.farthest[b], range(truth.circle.bins[b]));
      out.nearest[b] = std::min(out.nearest[b], range(truth.circle.bins[b]));
    }
  }
  return out;
}

// What the maps are given: the camera's depth image (and its points), or its points only, as
// an unorganised cloud from a recording arrives, or the points of every kRingRows-th image row
// only, as a spinning lidar's rings (Open3D's TSDF integrates images only).
enum class Input { kImage, kCloud, kRings };
constexpr int kRingRows = 8;  // 2.3 degrees apart: a 16-ring lidar's rings are 2 degrees apart

// The frame as `input` says the maps get it.
void keep_input(Input input, Frame& frame) {
  if (input != Input::kImage) sim::keep_cloud(frame, input == Input::kRings ? kRingRows : 1);
}

using MapperMaker = std::function<std::unique_ptr<Mapper>()>;
std::vector<std::pair<std::string, MapperMaker>> mappers(Input input) {
  std::vector<std::pair<std::string, MapperMaker>> list = {{"vdb_gpdf", [] { return std::make_unique<VdbGpdf>(); }},
                                                           {"tsdf", [] { return std::make_unique<Tsdf>(); }}};
  if (input == Input::kImage) list.emplace_back("open3d", [] { return std::make_unique<Open3dTsdf>(); });
  return list;
}

// The listener's raster origin at the head's pose (heading in degrees, as head_pose gives it).
RasterOrigin origin_at(const Eigen::Isometry3d& camera, double heading_deg) {
  RasterOrigin origin;
  origin.position = camera.translation();
  origin.heading = heading_deg * M_PI / 180.0;
  return origin;
}

// The circle a map gives around `origin` (held by the rasteriser until its next reset).
const Circle& circle_of(const Mapper& map, const RasterOrigin& origin, Rasteriser& rasteriser) {
  std::vector<Eigen::Vector3f> samples;
  map.surface_points(origin.position, rasteriser.config().max_range, samples);
  rasteriser.reset(origin);
  rasteriser.add(samples);
  return rasteriser.circle();
}

// Runs every mapper through one room; adds each evaluated bin to the tallies (one per mapper).
void run_room(uint64_t seed, Input input, std::vector<Tally>& tallies) {
  const Room room = random_room(seed);
  const RasterConfig config;
  std::vector<std::unique_ptr<Mapper>> maps;
  for (const auto& m : mappers(input)) maps.push_back(m.second());
  Rasteriser rasteriser(config);
  for (int i = 0; i < kFrames; ++i) {
    double heading = 0.0;
    const Eigen::Isometry3d camera = head_pose(room, i, &heading);
    const std::vector<Obstacle> now = room.at(i);
    const Scene scene = scene_of(now);
    Frame frame = test::render(scene, camera, i, kWidth, kHeight, 5.0, true);
    keep_input(input, frame);
    for (auto& map : maps) map->integrate(frame);
    if (i < 6 || i % 3 != 2) continue;  // evaluate every third frame once the map has a start
    const RasterOrigin origin = origin_at(camera, heading);
    std::vector<Box> boxes{scene.boxes.begin() + 1, scene.boxes.end()};  // not the floor
    const std::vector<eval::GroundTruthTriangle> triangles = triangles_of(boxes);
    const auto truth = eval::ground_truth_rasters(triangles, origin, config);
    const ResolvableTruth resolvable = resolvable_truth(triangles, truth.circle, origin, config);
    const auto old_place = eval::ground_truth_rasters(triangles_of({room.mover_before}), origin, config);
    for (size_t m = 0; m < maps.size(); ++m) {
      const Circle& circle = circle_of(*maps[m], origin, rasteriser);
      for (int b = 0; b < config.azimuth_bins; ++b) {
        const RasterCell& t = truth.circle.bins[b];
        if (!t.known()) continue;
        const Eigen::Vector3d p = t.point.cast<double>();
        const Obstacle* on = nullptr;
        for (const auto& o : now)
          if (inside(o.box, p)) on = &o;
        if (!on) continue;  // cannot happen: the truth point lies on a box
        std::array<bool, kClassCount> c = classify(*on, p, scene, camera);
        c[kVacated] = i >= kMoveFrame && !c[kOutOfView] && old_place.circle.bins[b].known() &&
                      old_place.circle.bins[b].range < t.range - kOff;
        const RasterCell& r = circle.bins[b];
        const bool strict_far = !r.known() || r.range > t.range + kOff;
        const bool far = strict_far && std::isfinite(resolvable.farthest[b]) &&
                         (!r.known() || r.range > resolvable.farthest[b] + kOff);
        const bool strict_near = r.range < t.range - kOff;
        const bool near = strict_near && r.range < resolvable.nearest[b] - kOff;
        const bool off = far || strict_near;
        for (int k = 0; k < kClassCount; ++k)
          if (c[k]) {
            ++tallies[m].bins[k];
            tallies[m].off[k] += off;
            tallies[m].far[k] += far;
            tallies[m].strict_far[k] += strict_far;
            tallies[m].near[k] += near;
          }
      }
    }
  }
}

std::string percent(int part, int whole) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << (whole ? 100.0 * part / whole : 0.0) << " %";
  return s.str();
}

// The seeds to run: 1 .. `rooms`, or "first-last" from SONOMAP_FIDELITY_SEEDS (1 <= first <=
// last <= 10000; anything else fails the test rather than running other rooms than asked for).
std::pair<uint64_t, uint64_t> seed_range(int rooms) {
  const char* text = std::getenv("SONOMAP_FIDELITY_SEEDS");
  if (!text) return {1, rooms};
  unsigned long first = 0, last = 0;
  int used = 0;
  const bool parsed = std::sscanf(text, "%lu-%lu%n", &first, &last, &used) == 2 && text[used] == '\0';
  INFO("SONOMAP_FIDELITY_SEEDS=" << text << ": expected first-last, 1 <= first <= last <= 10000");
  REQUIRE((parsed && first >= 1 && first <= last && last <= 10000));
  return {first, last};
}

// Runs the seeded rooms (1 .. `rooms`), prints the per-class table (docs/fidelity.md) and checks
// that in each of `classes` VDB-GPDF reads no more bins too far than the TSDF peer and than
// Open3D's ScalableTSDFVolume (images only), and in each of `near_classes` no more bins too near.
void check_classes(std::initializer_list<int> classes, std::initializer_list<int> near_classes, Input input,
                   int rooms) {
  const auto makers = mappers(input);
  std::vector<Tally> tallies(makers.size());
  const auto [first, last] = seed_range(rooms);
  for (uint64_t seed = first; seed <= last; ++seed) run_room(seed, input, tallies);
  std::ostringstream table;
  table << "| class | bins |";
  for (const auto& m : makers) table << ' ' << m.first << " off > 0.1 m (too far; strict; near) |";
  table << "\n|---|---|";
  for (size_t m = 0; m < makers.size(); ++m) table << "---|";
  table << '\n';
  for (int k = 0; k < kClassCount; ++k) {
    table << "| " << kClassNames[k] << " | " << tallies[0].bins[k] << " |";
    for (const Tally& t : tallies)
      table << ' ' << t.off[k] << ", " << percent(t.off[k], t.bins[k]) << " (" << t.far[k] << "; "
            << t.strict_far[k] << "; near " << t.near[k] << ") |";
    table << '\n';
  }
  WARN(table.str());
  for (size_t peer = 1; peer < makers.size(); ++peer)
    for (int k : classes) {
      INFO(kClassNames[k] << ": too far vdb_gpdf " << tallies[0].far[k] << ", "
                          << makers[peer].first << ' ' << tallies[peer].far[k] << " of "
                          << tallies[0].bins[k]);
      CHECK(tallies[0].bins[k] > 0);
      CHECK(tallies[0].far[k] <= tallies[peer].far[k]);
    }
  for (size_t peer = 1; peer < makers.size(); ++peer)
    for (int k : near_classes) {
      INFO(kClassNames[k] << ": too near vdb_gpdf " << tallies[0].near[k] << ", "
                          << makers[peer].first << ' ' << tallies[peer].near[k] << " of "
                          << tallies[0].bins[k]);
      CHECK(tallies[0].near[k] <= tallies[peer].near[k]);
    }
}

}  // namespace

// Too near, VDB-GPDF's surfaces run up to half a voxel past a box's corner or a panel's end
// seen end on, and at low boxes that read 3 bins too near against the peers' 2 in twelve rooms
// (of 630; docs/fidelity.md, "Twelve rooms"); in forty, 53 against 56 (of 1898).
TEST_CASE("Fidelity: in random box rooms VDB-GPDF reads no more bins too far than the TSDF "
          "peer or Open3D's TSDF at corners, low boxes, thin slabs, grazing faces and where a "
          "box left, and no more too near",
          "[fidelity]") {
  check_classes({kCorner, kLow, kThin, kGrazing, kVacated}, {kCorner, kLow, kThin, kGrazing, kVacated}, Input::kImage,
                kImageRooms);
}

// The same rooms from points only: VDB-GPDF then sees its frame's surfaces in a range image of
// its own (a cube of cells around the camera). Without it, every check against the image was
// skipped for clouds: rays carved the edges off and the circle read too far at 28 corner bins
// of 410, 22 thin ones, 8 low and 15 grazing (main f8f54f6; the TSDF peer 6, 5, 1 and 0).
// Too near, it reads more bins than the ray-traced peer, which reads none in any class: the
// lateral votes widen table legs and panels' ends by up to a voxel (4, 5, 4, 6 and 5 bins in
// twelve rooms; 9, 12, 16, 13 and 5 while they also ran past the view's edge: docs/fidelity.md,
// "Lateral votes beyond the view"). No class of readings too near is held.
TEST_CASE("Fidelity: from point clouds, in random box rooms VDB-GPDF reads no more bins too far than the TSDF "
          "peer at corners, low boxes, thin slabs, grazing faces and where a box left",
          "[fidelity]") {
  check_classes({kCorner, kLow, kThin, kGrazing, kVacated}, {}, Input::kCloud, kRooms);
}

// A lidar's rings meet a surface along lines 2.3 degrees apart (8 cm at 2 m). Along one line
// any plane through it fits the points, and VDB-GPDF took its normals from a ball that holds
// one ring only; with the rings one image row each (sim::keep_cloud) it read too far at 37
// corner bins, 52 low, 106 thin, 25 grazing and 4 where the box left (main 786c751), the TSDF
// peer at 6, 0, 9, 0 and 2. A ring's normal now reaches the next ring, and a plane through the
// sensor (a ring's own scan plane) is no normal. In 24 rooms: 14, 4, 32, 15 and 0 bins, the
// peer 46, 5, 57, 24 and 2. Too near, objects from rings come out wider (lateral votes), but
// where the box left VDB-GPDF reads fewer bins too near than the peer (31 against 193).
TEST_CASE("Fidelity: from a lidar's rings, in random box rooms VDB-GPDF reads no more bins too far "
          "than the TSDF peer at corners, low boxes, thin slabs, grazing faces and where a box left, "
          "and no more too near where a box left",
          "[fidelity]") {
  check_classes({kCorner, kLow, kThin, kGrazing, kVacated}, {kVacated}, Input::kRings, kRingRooms);
}

namespace {

// Room `seed` with its walls and only the furniture `keep` selects (`count` boxes with the
// walls). No box jumps: the mover, shrunk to 0.2 x 0.2 x 0.3 m, stays in a corner of the room.
Room part_of_room(uint64_t seed, const std::function<bool(const Box&)>& keep, size_t count) {
  Room room = random_room(seed);
  std::vector<Obstacle> kept;
  for (const Obstacle& o : room.obstacles)
    if (o.wall || keep(o.box)) kept.push_back(o);
  REQUIRE(kept.size() == count);
  room.obstacles = kept;
  room.mover_before = room.mover_after = footprint_box(-3.0, 3.0, 0.2, 0.2, 0.0, 0.3);
  return room;
}

// The head's walk through a static room with `map` given `input`; `look` sees each frame's
// index, camera, the listener's origin and the circle.
void walk(const Room& room, Input input, Mapper& map,
          const std::function<void(int, const Eigen::Isometry3d&, const RasterOrigin&, const Circle&)>& look) {
  const Scene scene = scene_of(room.at(0));
  Rasteriser rasteriser;
  for (int i = 0; i < kFrames; ++i) {
    double heading = 0.0;
    const Eigen::Isometry3d camera = head_pose(room, i, &heading);
    Frame frame = test::render(scene, camera, i, kWidth, kHeight, 5.0, true);
    keep_input(input, frame);
    map.integrate(frame);
    const RasterOrigin origin = origin_at(camera, heading);
    look(i, camera, origin, circle_of(map, origin, rasteriser));
  }
}

std::vector<Box> boxes_of(const std::vector<Obstacle>& obstacles) {
  std::vector<Box> boxes;
  for (const Obstacle& o : obstacles) boxes.push_back(o.box);
  return boxes;
}

}  // namespace

// Room 10's table alone (a 4 cm top on 5 cm legs, a 3 cm panel beside it, the walls): from the
// walk's dense clouds the top's corner stays just below the view, where no later frame looks.
// Lateral votes carried the top's plane a voxel past the corner, beyond what the cloud
// measured, and the circle read the table up to 7.6 cm beside it, 0.9-3.2 m nearer than the
// wall behind (docs/fidelity.md, "Lateral votes beyond the view"). A lateral vote now stands
// only where the cloud measured around it, or up to a voxel past the view's edge where the
// surface ran on to it.
TEST_CASE("Fidelity: from a dense cloud, a table whose corner stays just below the view reads "
          "nowhere a voxel or more beside the table",
          "[fidelity]") {
  const Room room = part_of_room(10, [](const Box& b) {  // the table (top and legs) and the panel
    return b.lo.x() > 0.09 && b.lo.x() < 1.3 && b.lo.y() > -2.2 && b.hi.y() < -0.99 && b.hi.z() < 0.74;
  }, 4 + 5 + 1);
  const std::vector<Box> now = boxes_of(room.at(0));
  double farthest_outside = 0.0;
  int readings = 0;
  VdbGpdf map;
  walk(room, Input::kCloud, map, [&](int, const Eigen::Isometry3d&, const RasterOrigin&, const Circle& circle) {
    for (const RasterCell& r : circle.bins) {
      if (!r.known()) continue;
      const Eigen::Vector3d p = r.point.cast<double>();
      double outside = HUGE_VAL;  // across the floor, to the nearest box's footprint (walls included)
      for (const Box& b : now)
        outside = std::min(outside, (b.lo - p).cwiseMax(p - b.hi).cwiseMax(0.0).head<2>().norm());
      farthest_outside = std::max(farthest_outside, outside);
      ++readings;
    }
  });
  INFO(readings << " readings in " << kFrames << " frames; the farthest lies " << farthest_outside
                << " m beside every box");
  CHECK(readings > 1000);
  CHECK(farthest_outside < VdbGpdfConfig().global_voxel);
}

// Room 24's table alone (a 1.3 x 0.95 m top 0.77 m high, 2 m ahead, on four legs, the walls).
// Looking 15 degrees down, the rings (2.3 degrees apart) cross the top about 25 cm apart, and
// the ball and the widened neighbourhood of surface_normal held one ring each: no normal, and a
// source without a normal casts no lateral vote. The top held only voxels on its rings, and of
// its bins in view 159 of 505 (31%) read more than 0.1 m too far: its edges lay up to a ring's
// spacing past where the map ended. A ring's normal now reaches the next rings through the
// cloud's range image where they show the surface going on (LeafQueries::plane_to_next_rings):
// 66 (13%), and 41 (8%) since a ring's own scan plane is no normal. Still too far: the near
// edge where it falls between two rings, and bins that cross the top's far corner between two
// rings (the TSDF peer, whose rays cross its truncation band along the line of sight, 15;
// docs/fidelity.md, "Rings far apart on a table top").
TEST_CASE("Fidelity: from a lidar's rings 25 cm apart across a table top, fewer than one in ten "
          "of the top's bins read more than 0.1 m too far",
          "[fidelity]") {
  const Room room = part_of_room(24, [](const Box& b) {  // the table: top and legs
    return b.lo.x() > 1.52 && b.hi.x() < 2.83 && b.lo.y() > -1.97 && b.hi.y() < -1.01 && b.hi.z() < 0.78;
  }, 4 + 5);
  const std::vector<eval::GroundTruthTriangle> triangles = triangles_of(boxes_of(room.at(0)));
  const Obstacle top = room.obstacles[4];  // after the 4 walls: random_room adds a top before its legs
  const Scene scene = scene_of(room.at(0));
  int on_top = 0, too_far = 0;
  VdbGpdf map;
  walk(room, Input::kRings, map, [&](int i, const Eigen::Isometry3d& camera, const RasterOrigin& origin,
                                const Circle& circle) {
    if (i < 6) return;  // the map's start
    const RasterConfig config;
    const Circle truth = eval::ground_truth_rasters(triangles, origin, config).circle;
    const ResolvableTruth resolvable = resolvable_truth(triangles, truth, origin, config);
    for (int b = 0; b < config.azimuth_bins; ++b) {
      const RasterCell& t = truth.bins[b];
      if (!t.known() || !inside(top.box, t.point.cast<double>()) ||
          classify(top, t.point.cast<double>(), scene, camera)[kOutOfView])
        continue;  // another box's bin, or the top's out of view
      ++on_top;
      const RasterCell& r = circle.bins[b];
      too_far += !r.known() || r.range > resolvable.farthest[b] + kOff;
    }
  });
  INFO(on_top << " bins in view on the table top in frames 6-23, " << too_far
              << " of them read more than 0.1 m too far");
  CHECK(on_top > 100);
  CHECK(10 * too_far < on_top);
}
