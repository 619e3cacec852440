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
#include <string>

namespace sonomap::harness {

// Parses a circle CSV; InputError naming the file, line and column on any deviation
// (wrong header, bin count or order, NaN, negative or unparsable range).
Circle parse_circle_csv(const std::string& text, const std::string& file_name);
Circle read_circle_csv(const std::filesystem::path& file);

// The CSV text of a circle (unknown bins empty), and an atomic write of it.
std::string circle_csv(const Circle& circle);
void write_circle_csv(const std::filesystem::path& file, const Circle& circle);

}  // namespace sonomap::harness
