// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/circle_io.hpp"

#include "harness/support/errors.hpp"
#include "harness/support/output.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace sonomap::harness {

static std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
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
    if (!range_text.empty()) {
      errno = 0;
      const double range = std::strtod(range_text.c_str(), &end);
      if (*end != '\0' || errno != 0)
        throw InputError(file, line_no, "range", "not a number: '" + range_text + "'");
      if (!std::isfinite(range) || range < 0.0)
        throw InputError(file, line_no, "range",
                         "must be a finite range >= 0 (leave it empty for unknown), got '" +
                             range_text + "'");
      circle.bins[static_cast<size_t>(bin)].range = static_cast<float>(range);
    }
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

}  // namespace sonomap::harness
