// SPDX-License-Identifier: GPL-3.0-or-later
// report.html: the report as one page a browser opens from disk (relative links only, no
// script, nothing from the network): per walk (scenario and seed), each run's video, its
// listening stream and sweeps as audio players, side by side to A/B by ear, and its pictures;
// then the plots. Written by `sonomap report` beside report.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace sonomap::harness {

struct HtmlRun {
  std::string id;  // folder name under <dir>/runs
  std::string scenario, variant, mapper;
  std::uint64_t seed = 0;
};

// Writes <dir>/report.html for `runs` (in this order within each walk) and <dir>/plots/*.png.
void write_report_html(const std::filesystem::path& dir, const std::vector<HtmlRun>& runs);

}  // namespace sonomap::harness
