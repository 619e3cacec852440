// SPDX-License-Identifier: GPL-3.0-or-later
// Kinect v1 style depth noise, as separate stages. Each stage is a pure function of its input
// image(s) and a random stream key; rows draw from their own streams, so results do not depend
// on the thread count. Order (sim docs): lateral jitter -> axial noise -> disparity
// quantisation -> invalidation (grazing, edges; range in DepthCamera) -> random dropout.
#pragma once

#include "sim/depth_camera.hpp"
#include "sim/random.hpp"
#include "sim/scenario.hpp"

#include <cstdint>

namespace sonomap::sim {

// Identifies a frame's random streams; each stage adds its StreamPurpose and the row.
struct NoiseKey {
  std::uint64_t seed = 1;
  std::uint64_t sensor = 0;
  std::uint64_t frame = 0;
};

// Nguyen, Izadi, Lovell 2012, "Modeling Kinect Sensor Noise for Improved 3D Reconstruction
// and Tracking": axial sigma_z(z, theta) = 0.0012 + 0.0019 (z - 0.4)^2 m, plus
// 0.0001 / sqrt(z) * theta^2 / (pi/2 - theta)^2 for theta > 60 degrees.
double axial_sigma(double z, double theta);
// Same paper: lateral sigma_L(theta) = 0.8 + 0.035 theta / (pi/2 - theta) pixels.
double lateral_sigma_px(double theta);

// Each pixel takes the depth (and incidence) of the pixel at a normally distributed offset of
// sigma_L(theta) pixels in u and v, rounded to the nearest pixel and clamped to the image.
DepthImage jitter_lateral(const DepthImage& in, const NoiseKey& key);
// z + N(0, axial_sigma(z, theta)) on returning pixels; a result <= 0 becomes no return.
DepthImage add_axial_noise(const DepthImage& in, const NoiseKey& key);
// Khoshelham & Elberink 2012, "Accuracy and Resolution of Kinect Depth Data": depth comes
// from disparity d = f b / z measured in steps of `step` pixels (1/8 on Kinect v1), so
// z' = f b / (step * round(f b / (z step))).
DepthImage quantise_disparity(const DepthImage& in, double focal_px, double baseline, double step);
// Pixels seen at an incidence angle beyond `max_angle` (radians) return nothing.
DepthImage invalidate_grazing(const DepthImage& in, double max_angle);
// Pixels that sit on a depth discontinuity of the `reference` (true) image - a 4-neighbour
// more than `threshold` metres nearer or farther, or a neighbour with no surface - return nothing.
DepthImage invalidate_edges(const DepthImage& in, const DepthImage& reference, double threshold);
// Each returning pixel is dropped with probability p.
DepthImage drop_out(const DepthImage& in, double p, const NoiseKey& key);

// The whole model on an exact image (from DepthCamera::trace, before range limits).
// Model::None returns the input unchanged. Range limits are applied by the caller.
// All stages run fused in one pass per row, the same image as running them one by one.
// `out` is overwritten, its buffers reused.
// The row loops run vectorised (vector_isa(); the same bits with any instruction set).
void apply_noise(const DepthImage& truth, const NoiseSpec& spec, double focal_px, const NoiseKey& key,
                 DepthImage& out);
DepthImage apply_noise(const DepthImage& truth, const NoiseSpec& spec, double focal_px, const NoiseKey& key);

}  // namespace sonomap::sim
