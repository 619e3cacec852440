// SPDX-License-Identifier: GPL-3.0-or-later
// The circle CSV: one row per 1-degree bin (docs/conventions.md), header line "bin,range", exactly
// 360 rows with bins 0..359 in order; range in metres, empty when the bin is unknown.
//   bin,range
//   0,2.000
//   1,
//   ...
#pragma once

#include "core/raster.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace sonomap::harness {

// Parses a circle CSV; InputError naming the file, line and column on any deviation
// (wrong header, bin count or order, NaN, negative or unparsable range).
Circle parse_circle_csv(const std::string& text, const std::string& file_name);
Circle read_circle_csv(const std::filesystem::path& file);

// The CSV text of a circle (unknown bins empty), and an atomic write of it.
std::string circle_csv(const Circle& circle);
void write_circle_csv(const std::filesystem::path& file, const Circle& circle);

}  // namespace sonomap::harness

namespace sonomap::harness {

// The rasters a run writes (run.hpp, circle.csv / cylinder.csv) and `score` reads, from any
// program: header "frame,bin,estimate" (circle) or "frame,row,bin,estimate" (cylinder), an
// optional extra "truth" column (ignored), one row per cell, range in metres, empty when
// unknown. Every listed frame must list each of its cells exactly once.
struct RasterFrames {
  int rows = 0;  // 0: circle rows (frame,bin,...)
  int bins = 0;
  std::map<int, std::vector<RasterCell>> frames;  // frame -> cells, row-major (row * bins + bin)
};

// Reads such a file; `rows` = 0 for the circle. InputError "file:line: key: what" on a missing
// or wrong header, a frame outside [0, frame_count), a row or bin out of range, a range that is
// NaN, infinite, negative or not a number, a duplicate cell, or a frame with missing cells.
RasterFrames read_raster_frames(const std::filesystem::path& file, int rows, int bins, int frame_count);

}  // namespace sonomap::harness
