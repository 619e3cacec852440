// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/world.hpp"

#include "sim/primitives.hpp"
#include "sim/trajectory.hpp"
#include "core/vector_isa.hpp"
#include "sim/world_geometry.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace sonomap::sim {

namespace {

void throw_on_device_error(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("embree: ") + what + " failed (error " +
                             std::to_string(static_cast<int>(error)) + ")");
}

// The packet World::cast traces by default: 16 rays where Embree traces them natively on this
// CPU (its AVX-512 kernels), else 8.
World::Packet native_packet(RTCDevice device) {
  return rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0 ? World::Packet::Rays16
                                                                                       : World::Packet::Rays8;
}

// A scene holding one triangle geometry with `mesh` placed by `transform`.
RTCScene make_mesh_scene(RTCDevice device, const TriangleMesh& mesh, const Eigen::Isometry3d& transform,
                         RTCBuildQuality quality) {
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene, quality);
  if (!mesh.triangles.empty()) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geometry, quality);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.triangles.size()));
    throw_on_device_error(device, "allocating mesh buffers");
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      const Eigen::Vector3f v = (transform * mesh.vertices[i].cast<double>()).cast<float>();
      std::memcpy(vertices + 3 * i, v.data(), 3 * sizeof(float));
    }
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
      for (int c = 0; c < 3; ++c) indices[3 * i + c] = static_cast<unsigned>(mesh.triangles[i][c]);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(scene);
  throw_on_device_error(device, "building a scene");
  return scene;
}

// Appends mesh b (already in the frame of a) to a.
void append_mesh(TriangleMesh& a, const TriangleMesh& b, const Eigen::Isometry3d& a_T_b) {
  const int offset = static_cast<int>(a.vertices.size());
  for (const Eigen::Vector3f& v : b.vertices) a.vertices.push_back((a_T_b * v.cast<double>()).cast<float>());
  for (const Eigen::Vector3i& t : b.triangles) a.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
}

}  // namespace

struct World::Impl {
  struct Mover {
    const MovingObject* spec = nullptr;
    RTCScene scene = nullptr;
    RTCGeometry instance = nullptr;
    unsigned instance_id = RTC_INVALID_GEOMETRY_ID;
  };

  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  RTCScene statics = nullptr;
  unsigned statics_id = RTC_INVALID_GEOMETRY_ID;  // the statics' instance in `top`
  // The scene rays are cast into: `top`, or without movers the statics themselves (no
  // instance to traverse; the same hits, as the statics' instance transform is the identity).
  RTCScene traced = nullptr;
  std::vector<Mover> movers;
  // World rotation of each instance by its geometry id in `top` (to bring Embree's
  // object-space Ng into the world frame).
  std::vector<Eigen::Matrix3f> instance_rotation;
  World::Packet native = World::Packet::Rays8;  // what Packet::Native stands for (native_packet)

  ~Impl() {
    for (Mover& m : movers)
      if (m.scene) rtcReleaseScene(m.scene);
    if (statics) rtcReleaseScene(statics);
    if (top) rtcReleaseScene(top);
    if (device) rtcReleaseDevice(device);
  }

  unsigned add_instance(RTCScene child, RTCGeometry& out) {
    out = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(out, child);
    rtcSetGeometryTimeStepCount(out, 1);
    set_transform(out, Eigen::Isometry3d::Identity());
    const unsigned id = rtcAttachGeometry(top, out);
    rtcReleaseGeometry(out);  // the top scene keeps it alive
    if (instance_rotation.size() <= id) instance_rotation.resize(id + 1, Eigen::Matrix3f::Identity());
    return id;
  }

  static void set_transform(RTCGeometry instance, const Eigen::Isometry3d& pose) {
    const Eigen::Matrix<float, 3, 4> m = pose.matrix().topRows<3>().cast<float>();  // column-major
    rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m.data());
  }
};

int native_packet_rays() {
  RTCDevice device = rtcNewDevice(nullptr);
  if (!device) throw std::runtime_error("embree: could not create a device");
  const World::Packet packet = native_packet(device);
  rtcReleaseDevice(device);
  return packet == World::Packet::Rays16 ? 16 : 8;
}

World::World(const Scenario& scenario) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.device = rtcNewDevice(nullptr);
  if (!w.device) throw std::runtime_error("embree: could not create a device");
  w.native = native_packet(w.device);
  w.top = rtcNewScene(w.device);
  rtcSetSceneFlags(w.top, RTC_SCENE_FLAG_ROBUST);

  // All statics merged into one world-frame mesh, built once at high quality.
  TriangleMesh merged;
  for (const StaticObject& object : scenario.statics) {
    const TriangleMesh mesh = mesh_of(object.shape, object.mesh);
    validate(mesh);
    append_mesh(merged, mesh, object.pose);
  }
  w.statics = make_mesh_scene(w.device, merged, Eigen::Isometry3d::Identity(), RTC_BUILD_QUALITY_HIGH);
  RTCGeometry static_instance = nullptr;
  w.statics_id = w.add_instance(w.statics, static_instance);
  rtcCommitGeometry(static_instance);

  w.movers.reserve(scenario.movers.size());
  for (const MovingObject& spec : scenario.movers) {
    const TriangleMesh mesh = mesh_of(spec.shape, spec.mesh);
    validate(mesh);
    validate(spec.trajectory);
    Impl::Mover m;
    m.spec = &spec;
    m.scene = make_mesh_scene(w.device, mesh, Eigen::Isometry3d::Identity(), RTC_BUILD_QUALITY_HIGH);
    m.instance_id = w.add_instance(m.scene, m.instance);
    w.movers.push_back(m);
  }
  w.traced = w.movers.empty() ? w.statics : w.top;
  set_time(0.0);
  throw_on_device_error(w.device, "building the world");
}

World::~World() = default;

void World::set_time(double t) {
  Impl& w = *impl_;
  for (Impl::Mover& m : w.movers) {
    if (is_present(*m.spec, t)) {
      const Eigen::Isometry3d pose = pose_at(m.spec->trajectory, t);
      Impl::set_transform(m.instance, pose);
      w.instance_rotation[m.instance_id] = pose.linear().cast<float>();
      rtcEnableGeometry(m.instance);
    } else {
      rtcDisableGeometry(m.instance);
    }
    rtcCommitGeometry(m.instance);
  }
  rtcCommitScene(w.top);
}

namespace {

// A tile of pixels is one Embree ray packet (World::Packet): 4x4 pixels and rtcIntersect16,
// native with AVX-512 (on the AVX-512 machine of docs/performance.md 40% less time than
// rtcIntersect8 on 4x2 tiles), or 4x2 pixels and rtcIntersect8, native with AVX2 (on a Zen 3
// core, which has no AVX-512, 10% less time than 16-ray packets; 8x1 tiles the same, 2x2 tiles
// and rtcIntersect4 1.5x).
struct Tiles16 {
  static constexpr int kW = 4, kH = 4;
  using RayHit = RTCRayHit16;
  static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rays) {
    rtcIntersect16(valid, scene, context, rays);
  }
};
struct Tiles8 {
  static constexpr int kW = 4, kH = 2;
  using RayHit = RTCRayHit8;
  static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rays) {
    rtcIntersect8(valid, scene, context, rays);
  }
};

// One packet of kW x kH rays: pixel i of the packet is (u0 + i % kW, v0 + i / kW).
template <class Tiles>
struct RayPacket {
  static constexpr int kSize = Tiles::kW * Tiles::kH;
  alignas(64) typename Tiles::RayHit rayhit;
  alignas(64) int valid[kSize];  // Embree needs both aligned to the packet's bytes

  // The fields no intersection changes, set once: origin, interval start, time, mask, flags.
  explicit RayPacket(const Eigen::Vector3f& origin) {
    auto& ray = rayhit.ray;
    for (int i = 0; i < kSize; ++i) {
      ray.org_x[i] = origin.x();
      ray.org_y[i] = origin.y();
      ray.org_z[i] = origin.z();
      ray.tnear[i] = 0.0f;
      ray.time[i] = 0.0f;
      ray.mask[i] = 0xFFFFFFFFu;  // Debian's Embree has ray masks on: 0 would hit nothing
      ray.id[i] = static_cast<unsigned>(i);
      ray.flags[i] = 0;
    }
  }
};

// The rays' directions R (x_u, y_v, 1) (R = world_R_camera, x_u = (u - cx) / fx, y_v =
// (v - cy) / fy) as a column term R.col(0) x_u plus a row term R.col(1) y_v + R.col(2),
// summed in the order of Eigen's 3x3 float product, so that each ray is R * (x_u, y_v, 1) to
// the bit; one addition per component and ray. Padded to whole tiles.
struct RayDirections {
  RayDirections(const PinholeRays& rays, int columns, int rows)
      : column_x(columns), column_y(columns), column_z(columns), row(rows) {
    const Eigen::Matrix3f r = rays.world_T_camera.linear().cast<float>();
    for (int u = 0; u < columns; ++u) {
      const auto x = static_cast<float>((static_cast<double>(u) - rays.cx) / rays.fx);
      column_x[u] = r(0, 0) * x;
      column_y[u] = r(1, 0) * x;
      column_z[u] = r(2, 0) * x;
    }
    for (int v = 0; v < rows; ++v) {
      const auto y = static_cast<float>((static_cast<double>(v) - rays.cy) / rays.fy);
      row[v] = Eigen::Vector3f(r(0, 1) * y + r(0, 2), r(1, 1) * y + r(1, 2), r(2, 1) * y + r(2, 2));
    }
  }
  std::vector<float> column_x, column_y, column_z;
  std::vector<Eigen::Vector3f> row;
};

// A normal n seen through rotation r (Eigen's order for a 3x3 float product).
Eigen::Vector3f rotated(const Eigen::Matrix3f& r, float x, float y, float z) {
  return Eigen::Vector3f(r(0, 0) * x + (r(0, 1) * y + r(0, 2) * z), r(1, 0) * x + (r(1, 1) * y + r(1, 2) * z),
                         r(2, 0) * x + (r(2, 1) * y + r(2, 2) * z));
}

// One image row's incidence angles from its hit depths (+infinity: nothing hit, angle 0), the
// world normals n (x, y, z: one array each) and the ray directions d: acos of
// d.n / sqrt(|d|^2 |n|^2), in double (one root instead of two normalisations).
SONOMAP_VECTOR_LOOP void incidence_row(int width, const RayDirections& rays, int v, const float* __restrict z,
                                       const float* __restrict nx, const float* __restrict ny,
                                       const float* __restrict nz, float* __restrict incidence) {
  const float row_x = rays.row[v].x(), row_y = rays.row[v].y(), row_z = rays.row[v].z();
  const float* __restrict column_x = rays.column_x.data();
  const float* __restrict column_y = rays.column_y.data();
  const float* __restrict column_z = rays.column_z.data();
  for (int u = 0; u < width; ++u) {
    // The direction in float, as the ray was cast, then in double.
    const double d0 = column_x[u] + row_x, d1 = column_y[u] + row_y, d2 = column_z[u] + row_z;
    const double n0 = nx[u], n1 = ny[u], n2 = nz[u];
    const double dn = (d0 * n0 + d1 * n1) + d2 * n2;
    const double dd = (d0 * d0 + d1 * d1) + d2 * d2, nn = (n0 * n0 + n1 * n1) + n2 * n2;
    const float angle = incidence_angle(static_cast<float>(dn / std::sqrt(dd * nn)));
    incidence[u] = z[u] < std::numeric_limits<float>::infinity() ? angle : 0.0f;
  }
}

void incidence_row_baseline(int width, const RayDirections& rays, int v, const float* z, const float* nx,
                            const float* ny, const float* nz, float* incidence) {
  incidence_row(width, rays, v, z, nx, ny, nz, incidence);
}
SONOMAP_AVX2_KERNEL void incidence_row_avx2(int width, const RayDirections& rays, int v, const float* z,
                                            const float* nx, const float* ny, const float* nz, float* incidence) {
  incidence_row(width, rays, v, z, nx, ny, nz, incidence);
}
SONOMAP_AVX512_KERNEL void incidence_row_avx512(int width, const RayDirections& rays, int v, const float* z,
                                                const float* nx, const float* ny, const float* nz, float* incidence) {
  incidence_row(width, rays, v, z, nx, ny, nz, incidence);
}

// What a packet's rays are cast into: the scene and how to read a hit's normal in the world.
struct TracedScene {
  RTCScene scene;
  unsigned statics_id;                                     // the statics' instance (world frame)
  const std::vector<Eigen::Matrix3f>& instance_rotation;  // per instance, its rotation
};

// A tile row's world normals: x, y and z planes of kH image rows each, `row_stride` apart.
struct TileRowNormals {
  TileRowNormals(int row_stride, int rows)
      : row_stride(static_cast<std::size_t>(row_stride)), plane(rows * this->row_stride), xyz(3 * plane) {}
  float* x() { return xyz.data(); }
  float* y() { return xyz.data() + plane; }
  float* z() { return xyz.data() + 2 * plane; }
  std::size_t row_stride, plane;
  std::vector<float> xyz;
};

// A tile row: kW = 4 pixels, one SSE vector (GCC's vector extensions), so that aiming and
// reading a packet are a few vector instructions per row instead of a loop per pixel.
typedef float Float4 __attribute__((vector_size(16)));
typedef std::int32_t Int4 __attribute__((vector_size(16)));
template <class T>
T load4(const void* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
void store4(void* p, const T& v) {
  std::memcpy(p, &v, sizeof v);
}
// A tile row of "nothing hit": tfar before a hit, the depth of a miss, and Embree's no-id.
const Float4 kNoHitDepth = Float4{} + std::numeric_limits<float>::infinity();
const Int4 kNoId = Int4{} + static_cast<std::int32_t>(RTC_INVALID_GEOMETRY_ID);

// Points packet (tx, ty)'s rays from the camera through its pixels; pixels beyond the image
// are off.
template <class Tiles>
void aim(RayPacket<Tiles>& packet, const RayDirections& directions, int tx, int ty, int width, int height) {
  static_assert(Tiles::kW == 4, "a tile row is one Float4");
  auto& ray = packet.rayhit.ray;
  const int u = tx * Tiles::kW;
  const auto column_x = load4<Float4>(&directions.column_x[u]);
  const auto column_y = load4<Float4>(&directions.column_y[u]);
  const auto column_z = load4<Float4>(&directions.column_z[u]);
  for (int row = 0; row < Tiles::kH; ++row) {
    const int v = ty * Tiles::kH + row, i = row * Tiles::kW;
    const Eigen::Vector3f& d = directions.row[v];
    store4(&ray.dir_x[i], column_x + d.x());
    store4(&ray.dir_y[i], column_y + d.y());
    store4(&ray.dir_z[i], column_z + d.z());
    store4(&packet.valid[i], (u + Int4{0, 1, 2, 3} < width) & (v < height ? -1 : 0));  // -1: on, as Embree wants
  }
  for (int i = 0; i < RayPacket<Tiles>::kSize; i += 4) {
    store4(&ray.tfar[i], kNoHitDepth);
    store4(&packet.rayhit.hit.geomID[i], kNoId);
    store4(&packet.rayhit.hit.instID[0][i], kNoId);
  }
}

// Lanes i .. i + 3 of the packet that hit a mover (an instance other than the statics'): -1.
template <class Hit>
Int4 mover_lanes(const Hit& hit, int i, unsigned statics_id) {
  const auto instance = load4<Int4>(&hit.instID[0][i]);
  return (load4<Int4>(&hit.geomID[i]) != kNoId) & (instance != kNoId) &
         (instance != static_cast<std::int32_t>(statics_id));
}

// Packet (tx, ty)'s hits as they come: the depth along each ray (+infinity: nothing hit) into
// the image, the normals into the tile row's planes. A tile on the image's border goes pixel
// by pixel.
template <class Tiles>
void read_hits(const RayPacket<Tiles>& packet, int tx, int ty, RayHits& hits, TileRowNormals& normals) {
  const auto& ray = packet.rayhit.ray;
  const auto& hit = packet.rayhit.hit;
  const bool whole = (tx + 1) * Tiles::kW <= hits.width && (ty + 1) * Tiles::kH <= hits.height;
  for (int row = 0; row < Tiles::kH; ++row) {
    const int v = ty * Tiles::kH + row, i = row * Tiles::kW;
    if (v >= hits.height) break;  // a tile on the image's last rows
    float* z = hits.z.data() + static_cast<std::size_t>(v) * hits.width + tx * Tiles::kW;
    const std::size_t at = row * normals.row_stride + tx * Tiles::kW;
    if (whole) {
      store4(z, load4<Int4>(&hit.geomID[i]) == kNoId ? kNoHitDepth : load4<Float4>(&ray.tfar[i]));
      std::memcpy(normals.x() + at, &hit.Ng_x[i], sizeof(Float4));
      std::memcpy(normals.y() + at, &hit.Ng_y[i], sizeof(Float4));
      std::memcpy(normals.z() + at, &hit.Ng_z[i], sizeof(Float4));
      continue;
    }
    for (int column = 0; column < Tiles::kW; ++column) {
      const int k = i + column;
      if (!packet.valid[k]) continue;
      z[column] = hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? ray.tfar[k] : std::numeric_limits<float>::infinity();
      normals.x()[at + column] = hit.Ng_x[k];
      normals.y()[at + column] = hit.Ng_y[k];
      normals.z()[at + column] = hit.Ng_z[k];
    }
  }
}

// Embree gives a mover's normal in the mover's frame (the statics' are in the world frame):
// packet (tx, ·)'s movers' normals turned into the world. Most tile rows hit no mover.
template <class Tiles>
void turn_mover_normals(const RayPacket<Tiles>& packet, const TracedScene& traced, int tx, TileRowNormals& normals) {
  const auto& hit = packet.rayhit.hit;
  for (int row = 0; row < Tiles::kH; ++row) {
    const int i = row * Tiles::kW;
    const Int4 movers = mover_lanes(hit, i, traced.statics_id) & load4<Int4>(&packet.valid[i]);
    if (!(movers[0] | movers[1] | movers[2] | movers[3])) continue;
    for (int column = 0; column < Tiles::kW; ++column) {
      const int k = i + column;
      if (!movers[column]) continue;
      const Eigen::Vector3f n = rotated(traced.instance_rotation[hit.instID[0][k]], hit.Ng_x[k], hit.Ng_y[k], hit.Ng_z[k]);
      const std::size_t at = row * normals.row_stride + tx * Tiles::kW + column;
      normals.x()[at] = n.x();
      normals.y()[at] = n.y();
      normals.z()[at] = n.z();
    }
  }
}

// Casts the image's rays in packets of Tiles' shape, rows of tiles spread over TBB threads.
template <class Tiles>
void cast_tiles(const TracedScene& traced, const PinholeRays& rays, RayHits& hits) {
  constexpr int kW = Tiles::kW, kH = Tiles::kH;
  const int width = rays.width, height = rays.height;
  const int tiles_x = (width + kW - 1) / kW;
  const int tiles_y = (height + kH - 1) / kH;
  const RayDirections directions(rays, tiles_x * kW, tiles_y * kH);
  const Eigen::Vector3f origin = rays.world_T_camera.translation().cast<float>();
  const auto incidence_of_row =
      kernel_for(vector_isa(), &incidence_row_baseline, &incidence_row_avx2, &incidence_row_avx512);

  tbb::parallel_for(tbb::blocked_range<int>(0, tiles_y), [&](const tbb::blocked_range<int>& range) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    RayPacket<Tiles> packet(origin);
    TileRowNormals normals(tiles_x * kW, kH);
    for (int ty = range.begin(); ty < range.end(); ++ty) {
      for (int tx = 0; tx < tiles_x; ++tx) {
        aim(packet, directions, tx, ty, width, height);
        Tiles::intersect(packet.valid, traced.scene, &context, &packet.rayhit);
        read_hits(packet, tx, ty, hits, normals);
        turn_mover_normals(packet, traced, tx, normals);
      }
      for (int row = 0; row < kH && ty * kH + row < height; ++row) {
        const int v = ty * kH + row;
        const std::size_t at = row * normals.row_stride, p = static_cast<std::size_t>(v) * width;
        incidence_of_row(width, directions, v, hits.z.data() + p, normals.x() + at, normals.y() + at, normals.z() + at,
                         hits.incidence.data() + p);
      }
    }
  });
}

}  // namespace

void World::cast(const PinholeRays& rays, RayHits& hits, Packet packet) const {
  hits.width = rays.width;
  hits.height = rays.height;
  hits.z.resize(static_cast<std::size_t>(rays.width) * rays.height);  // every pixel is written
  hits.incidence.resize(hits.z.size());
  const TracedScene traced{impl_->traced, impl_->statics_id, impl_->instance_rotation};
  if (packet == Packet::Native) packet = impl_->native;
  if (packet == Packet::Rays16) {
    cast_tiles<Tiles16>(traced, rays, hits);
  } else {
    cast_tiles<Tiles8>(traced, rays, hits);
  }
}

}  // namespace sonomap::sim
