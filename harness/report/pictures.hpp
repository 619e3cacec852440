// SPDX-License-Identifier: GPL-3.0-or-later
// Pictures a person would rather look at than CSV, drawn by gnuplot (pngcairo):
// the circle as a top view around the listener, the cylinder unrolled (azimuth x height).
#pragma once

#include "core/edf_raster.hpp"
#include "core/raster.hpp"
#include "core/types.hpp"

#include <filesystem>
#include <string>

namespace sonomap::harness {

// Top view, heading up (straight ahead is up, left is left). The estimate is a ring coloured by
// each bin's range (grey where unknown) and its selected closest points, coloured the same; the
// ground truth is a black outline at its range per bin.
void plot_circle(const std::filesystem::path& png, const Circle& estimate, const Circle* truth,
                 const RasterOrigin& origin, const RasterConfig& config, const std::string& title);

// The cylinder unrolled: azimuth across (ahead in the middle, left to the left), height up,
// coloured by range; unknown cells are left white.
void plot_cylinder(const std::filesystem::path& png, const Cylinder& estimate,
                   const RasterConfig& config, const std::string& title);

// The paper's Fig. "arrow_ours" next to "arrow_esdf", top view, heading up. Left: the map's
// circle as rays from the listener, each as long as its bin's range. Right: the EDF circle's
// sample points with arrows to their closest surface (-gradient, as long as the distance), and
// the sphere-traced ranges as points. One arrow every `arrow_step_deg` degrees.
void plot_edf_arrows(const std::filesystem::path& png, const Circle& map_circle,
                     const EdfRaster& edf, const RasterOrigin& origin, const RasterConfig& config,
                     const std::string& title, double arrow_step_deg = 5.0);

// Runs gnuplot on a script; throws std::runtime_error with gnuplot's message if it fails.
void run_gnuplot(const std::filesystem::path& script);

// Writes `script_text` beside `png` (as .gp), runs gnuplot on it and removes the script.
void draw_with_gnuplot(const std::filesystem::path& png, const std::string& script_text);

}  // namespace sonomap::harness
