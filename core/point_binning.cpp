// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/point_binning.hpp"

#include "core/vector_isa.hpp"

#include <cmath>

namespace sonomap {

namespace {

// Reads the camera points straight from their (x, y, z) floats: the batch holds no copy.
SONOMAP_VECTOR_LOOP void bin_batch(const float* xyz, size_t n, const PointBinner::Pose& pose, PointBinner::Batch& b) {
  const PointBinner::Pose at = pose;  // locals: a load inside a select could trap (see the top-level CMakeLists.txt)
  for (size_t i = 0; i < n; ++i) {
    const double cx = xyz[3 * i], cy = xyz[3 * i + 1], cz = xyz[3 * i + 2];
    const double r2 = (cx * cx + cy * cy) + cz * cz;
    // NaN and infinity fail one of the comparisons: such points are not fused.
    const bool fused = (r2 >= at.min2) & (r2 <= at.max2);
    // The sums associate as Eigen's 3x3 product did before this pass (rows 0 and 1 left to
    // right, row 2 from the right), so maps stayed the same to the bit.
    const double x = ((at.rotation[0] * cx + at.rotation[3] * cy) + at.rotation[6] * cz) + at.translation[0];
    const double y = ((at.rotation[1] * cx + at.rotation[4] * cy) + at.rotation[7] * cz) + at.translation[1];
    const double z = (at.rotation[2] * cx + (at.rotation[5] * cy + at.rotation[8] * cz)) + at.translation[2];
    b.x[i] = static_cast<float>(x);
    b.y[i] = static_cast<float>(y);
    b.z[i] = static_cast<float>(z);
    // A point that is not fused may lie anywhere (or nowhere): its voxel is 0, not converted.
    b.vx[i] = static_cast<int32_t>(fused ? std::floor(x * at.inverse_voxel) : 0.0);
    b.vy[i] = static_cast<int32_t>(fused ? std::floor(y * at.inverse_voxel) : 0.0);
    b.vz[i] = static_cast<int32_t>(fused ? std::floor(z * at.inverse_voxel) : 0.0);
    b.fused[i] = fused;
  }
}

void bin_baseline(const float* xyz, size_t n, const PointBinner::Pose& pose, PointBinner::Batch& b) {
  bin_batch(xyz, n, pose, b);
}
SONOMAP_AVX2_KERNEL void bin_avx2(const float* xyz, size_t n, const PointBinner::Pose& pose, PointBinner::Batch& b) {
  bin_batch(xyz, n, pose, b);
}
SONOMAP_AVX512_KERNEL void bin_avx512(const float* xyz, size_t n, const PointBinner::Pose& pose,
                                      PointBinner::Batch& b) {
  bin_batch(xyz, n, pose, b);
}

}  // namespace

PointBinner::PointBinner(double voxel, double min_range, double max_range,
                         const Eigen::Isometry3d& world_T_camera)
    : pose_{{}, {}, 1.0 / voxel, min_range * min_range, max_range * max_range} {
  Eigen::Map<Eigen::Matrix3d>(pose_.rotation) = world_T_camera.linear();
  Eigen::Map<Eigen::Vector3d>(pose_.translation) = world_T_camera.translation();
}

void PointBinner::bin(const Eigen::Vector3f* points, size_t n, Batch& out) const {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "points are packed (x, y, z) floats");
  kernel_for(vector_isa(), &bin_baseline, &bin_avx2, &bin_avx512)(reinterpret_cast<const float*>(points), n, pose_, out);
}

}  // namespace sonomap
