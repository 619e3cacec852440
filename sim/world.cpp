// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/world.hpp"

#include "sim/primitives.hpp"
#include "sim/trajectory.hpp"
#include "sim/world_geometry.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace sonomap::sim {

namespace {

// 4x2 pixel tiles = one rtcIntersect8 packet, AVX2's native width (rtcIntersect16 is emulated
// there and was slower).
constexpr int kTileW = 4, kTileH = 2, kPacket = kTileW * kTileH;

void throw_on_device_error(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("embree: ") + what + " failed (error " +
                             std::to_string(static_cast<int>(error)) + ")");
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
  std::vector<Mover> movers;
  // World rotation of each instance by its geometry id in `top` (to bring Embree's
  // object-space Ng into the world frame).
  std::vector<Eigen::Matrix3f> instance_rotation;

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

World::World(const Scenario& scenario) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.device = rtcNewDevice(nullptr);
  if (!w.device) throw std::runtime_error("embree: could not create a device");
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
  w.add_instance(w.statics, static_instance);
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

// One packet of kTileW x kTileH rays: pixel i of the packet is (u0 + i % kTileW, v0 + i / kTileW).
struct Packet {
  alignas(32) RTCRayHit8 rayhit;
  alignas(32) int valid[kPacket];  // rtcIntersect8 needs both 32-byte aligned
};

}  // namespace

void World::cast(const PinholeRays& rays, RayHits& hits) const {
  const Impl& w = *impl_;
  hits.width = rays.width;
  hits.height = rays.height;
  const std::size_t n = static_cast<std::size_t>(rays.width) * rays.height;
  hits.z.resize(n);  // every pixel is written below
  hits.incidence.resize(n);

  const Eigen::Matrix3f world_R_camera = rays.world_T_camera.linear().cast<float>();
  const Eigen::Vector3f origin = rays.world_T_camera.translation().cast<float>();
  const int tiles_x = (rays.width + kTileW - 1) / kTileW;
  const int tiles_y = (rays.height + kTileH - 1) / kTileH;
  // Optical-frame direction components per column and per row (padded to whole tiles).
  std::vector<float> x_of_column(static_cast<std::size_t>(tiles_x) * kTileW);
  std::vector<float> y_of_row(static_cast<std::size_t>(tiles_y) * kTileH);
  for (std::size_t u = 0; u < x_of_column.size(); ++u)
    x_of_column[u] = static_cast<float>((static_cast<double>(u) - rays.cx) / rays.fx);
  for (std::size_t v = 0; v < y_of_row.size(); ++v)
    y_of_row[v] = static_cast<float>((static_cast<double>(v) - rays.cy) / rays.fy);

  tbb::parallel_for(tbb::blocked_range<int>(0, tiles_y), [&](const tbb::blocked_range<int>& range) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    Packet packet;
    RTCRay8& ray = packet.rayhit.ray;
    RTCHit8& hit = packet.rayhit.hit;
    for (int ty = range.begin(); ty < range.end(); ++ty) {
      for (int tx = 0; tx < tiles_x; ++tx) {
        Eigen::Vector3f direction[kPacket];
        for (int i = 0; i < kPacket; ++i) {
          const int u = tx * kTileW + i % kTileW;
          const int v = ty * kTileH + i / kTileW;
          packet.valid[i] = (u < rays.width && v < rays.height) ? -1 : 0;
          direction[i] = world_R_camera * Eigen::Vector3f(x_of_column[u], y_of_row[v], 1.0f);
          ray.org_x[i] = origin.x();
          ray.org_y[i] = origin.y();
          ray.org_z[i] = origin.z();
          ray.dir_x[i] = direction[i].x();
          ray.dir_y[i] = direction[i].y();
          ray.dir_z[i] = direction[i].z();
          ray.tnear[i] = 0.0f;
          ray.tfar[i] = std::numeric_limits<float>::infinity();
          ray.time[i] = 0.0f;
          ray.mask[i] = 0xFFFFFFFFu;  // Debian's Embree has ray masks on: 0 would hit nothing
          ray.id[i] = static_cast<unsigned>(i);
          ray.flags[i] = 0;
          hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
          hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect8(packet.valid, w.top, &context, &packet.rayhit);
        float cosine[kPacket];  // of the incidence angle; 1 (angle 0) where nothing was hit
        for (int i = 0; i < kPacket; ++i) {
          cosine[i] = 1.0f;
          if (!packet.valid[i] || hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
          const Eigen::Vector3f ng(hit.Ng_x[i], hit.Ng_y[i], hit.Ng_z[i]);
          // cos = d.n / (|d| |n|) in double: one root and one division instead of two normalisations.
          const Eigen::Vector3d n = (w.instance_rotation[hit.instID[0][i]] * ng).cast<double>();
          const Eigen::Vector3d d = direction[i].cast<double>();
          cosine[i] = static_cast<float>(d.dot(n) / std::sqrt(d.squaredNorm() * n.squaredNorm()));
        }
        for (int i = 0; i < kPacket; ++i) {
          if (!packet.valid[i]) continue;
          const std::size_t p = static_cast<std::size_t>(ty * kTileH + i / kTileW) * rays.width + tx * kTileW + i % kTileW;
          const bool hit_something = hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
          hits.z[p] = hit_something ? ray.tfar[i] : std::numeric_limits<float>::infinity();
          hits.incidence[p] = incidence_angle(cosine[i]);
        }
      }
    }
  });
}

}  // namespace sonomap::sim
