// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/circle_io.hpp"

#include "harness/support/errors.hpp"
#include "harness/support/output.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace sonomap::harness {

static std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

// A range cell: empty is unknown; otherwise a finite number >= 0.
static float parse_range(const std::string& text, const std::string& file, int line,
                         const std::string& key) {
  if (text.empty()) return kUnknownRange;
  char* end = nullptr;
  errno = 0;
  const double range = std::strtod(text.c_str(), &end);
  if (*end != '\0' || errno != 0) throw InputError(file, line, key, "not a number: '" + text + "'");
  if (!std::isfinite(range) || range < 0.0)
    throw InputError(file, line, key,
                     "must be a finite range >= 0 (leave it empty for unknown), got '" + text + "'");
  return static_cast<float>(range);
}

Circle parse_circle_csv(const std::string& text, const std::string& file) {
  constexpr int kBins = 360;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  if (!std::getline(in, line)) throw InputError(file, 1, "", "empty file (expected header 'bin,range')");
  ++line_no;
  if (trim(line) != "bin,range")
    throw InputError(file, 1, "", "header must be 'bin,range', got '" + trim(line) + "'");
  Circle circle(kBins);
  int rows = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string row = trim(line);
    if (row.empty()) continue;  // blank lines (e.g. a trailing newline) carry no bin
    const size_t comma = row.find(',');
    if (comma == std::string::npos || row.find(',', comma + 1) != std::string::npos)
      throw InputError(file, line_no, "", "expected 'bin,range'");
    const std::string bin_text = trim(row.substr(0, comma));
    const std::string range_text = trim(row.substr(comma + 1));
    char* end = nullptr;
    errno = 0;
    const long bin = std::strtol(bin_text.c_str(), &end, 10);
    if (bin_text.empty() || *end != '\0' || errno != 0)
      throw InputError(file, line_no, "bin", "not an integer: '" + bin_text + "'");
    if (rows >= kBins)
      throw InputError(file, line_no, "bin", "more than " + std::to_string(kBins) + " rows");
    if (bin != rows)
      throw InputError(file, line_no, "bin", "expected bin " + std::to_string(rows) + ", got " +
                                                 std::to_string(bin) + " (bins 0..359 in order)");
    circle.bins[static_cast<size_t>(bin)].range = parse_range(range_text, file, line_no, "range");
    ++rows;
  }
  if (rows != kBins)
    throw InputError(file, line_no, "", "has " + std::to_string(rows) + " bins, expected " +
                                            std::to_string(kBins));
  return circle;
}

Circle read_circle_csv(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), 0, "", "cannot open the circle file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_circle_csv(text.str(), file.string());
}

std::string circle_csv(const Circle& circle) {
  std::string out = "bin,range\n";
  char buf[64];
  for (size_t k = 0; k < circle.bins.size(); ++k) {
    const float r = circle.bins[k].range;
    if (circle.bins[k].known())
      std::snprintf(buf, sizeof buf, "%zu,%.6g\n", k, static_cast<double>(r));
    else
      std::snprintf(buf, sizeof buf, "%zu,\n", k);
    out += buf;
  }
  return out;
}

void write_circle_csv(const std::filesystem::path& file, const Circle& circle) {
  write_text_file(file, circle_csv(circle));
}

static std::vector<std::string> split_fields(const std::string& row) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = row.find(',', start);
    fields.push_back(trim(row.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) return fields;
    start = comma + 1;
  }
}

// An integer field in [0, limit); InputError naming the line and key otherwise.
static int parse_index(const std::string& text, int limit, const std::string& file, int line,
                       const std::string& key) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0)
    throw InputError(file, line, key, "not an integer: '" + text + "'");
  if (v < 0 || v >= limit)
    throw InputError(file, line, key, "out of range: " + text + " (expected 0.." + std::to_string(limit - 1) + ")");
  return static_cast<int>(v);
}

RasterFrames read_raster_frames(const std::filesystem::path& path, int rows, int bins, int frame_count) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, 0, "", "cannot open the raster file");
  const std::vector<std::string> columns =
      rows > 0 ? std::vector<std::string>{"frame", "row", "bin", "estimate"}
               : std::vector<std::string>{"frame", "bin", "estimate"};
  std::string expected, line;
  for (const auto& c : columns) expected += (expected.empty() ? "" : ",") + c;
  int line_no = 1;
  if (!std::getline(in, line) || (trim(line) != expected && trim(line) != expected + ",truth"))
    throw InputError(file, 1, "", "header must be '" + expected + "' (or with ',truth'), got '" + trim(line) + "'");
  const std::size_t width = split_fields(trim(line)).size();
  RasterFrames out{rows, bins, {}};
  const int cells = std::max(rows, 1) * bins;
  std::map<int, std::vector<char>> seen;  // per frame: which cells a row gave
  while (std::getline(in, line)) {
    ++line_no;
    const std::string row_text = trim(line);
    if (row_text.empty()) continue;
    const std::vector<std::string> f = split_fields(row_text);
    if (f.size() != width) throw InputError(file, line_no, "", "expected " + std::to_string(width) + " fields");
    const int frame = parse_index(f[0], frame_count, file, line_no, "frame");
    const int row = rows > 0 ? parse_index(f[1], rows, file, line_no, "row") : 0;
    const int bin = parse_index(f[columns.size() - 2], bins, file, line_no, "bin");
    const std::size_t index = static_cast<std::size_t>(row) * bins + bin;
    std::vector<char>& frame_seen = seen[frame];
    frame_seen.resize(static_cast<std::size_t>(cells), 0);
    if (frame_seen[index]++)
      throw InputError(file, line_no, "", "duplicate cell (frame " + f[0] +
                                              (rows > 0 ? ", row " + f[1] : "") + ", bin " +
                                              f[columns.size() - 2] + ")");
    std::vector<RasterCell>& frame_cells = out.frames[frame];
    frame_cells.resize(static_cast<std::size_t>(cells));
    frame_cells[index].range = parse_range(f[columns.size() - 1], file, line_no, "estimate");
  }
  for (const auto& [frame, frame_seen] : seen) {
    const auto given = std::count(frame_seen.begin(), frame_seen.end(), 1);
    if (given != cells)
      throw InputError(file, 0, "", "frame " + std::to_string(frame) + " has " + std::to_string(given) +
                                        " of its " + std::to_string(cells) + " cells");
  }
  if (out.frames.empty()) throw InputError(file, line_no, "", "no rows");
  return out;
}

}  // namespace sonomap::harness
