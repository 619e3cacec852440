// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/report_html.hpp"

#include "harness/report/claims.hpp"
#include "harness/support/output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// A relative URL for a path under the report folder: each byte outside the unreserved set
// percent-encoded, '/' kept.
std::string url(const fs::path& relative) {
  std::string out;
  for (unsigned char c : relative.generic_string()) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~' || c == '/')
      out += static_cast<char>(c);
    else
      out += fmt::format("%{:02X}", c);
  }
  return out;
}

// The files in dir/sub ending in `suffix`, sorted by name, relative to `root`.
std::vector<fs::path> files(const fs::path& root, const fs::path& sub, const std::string& suffix) {
  std::vector<fs::path> found;
  const fs::path dir = root / sub;
  if (!fs::is_directory(dir)) return found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      found.push_back(sub / name);
  }
  std::sort(found.begin(), found.end());
  return found;
}

std::string audio_player(const fs::path& wav, const std::string& label) {
  return fmt::format("<figure><figcaption>{}</figcaption><audio controls preload=\"metadata\" "
                     "src=\"{}\"></audio></figure>\n",
                     xml_escape(label), url(wav));
}

// One run: its video, its listening stream, its sweeps and its pictures.
std::string run_section(const fs::path& dir, const HtmlRun& run) {
  const fs::path rel = fs::path("runs") / run.id;
  std::ostringstream html;
  html << "<section class=\"run\"><h3>" << xml_escape(run.variant) << "</h3>\n<p>run <code>"
       << xml_escape(run.id) << "</code>, mapper " << xml_escape(run.mapper) << "</p>\n";
  if (fs::is_regular_file(dir / rel / "run.mp4"))
    html << "<video controls preload=\"metadata\" width=\"640\" src=\"" << url(rel / "run.mp4")
         << "\"></video>\n";
  if (fs::is_regular_file(dir / rel / "listen.wav"))
    html << audio_player(rel / "listen.wav", "listening stream (listen.wav)");
  for (const fs::path& wav : files(dir, rel / "sweeps", ".wav"))
    html << audio_player(wav, "sweep " + wav.filename().string());
  for (const fs::path& png : files(dir, rel / "pictures", ".png"))
    html << "<figure><img src=\"" << url(png) << "\" alt=\"" << xml_escape(png.filename().string())
         << "\"><figcaption>" << xml_escape(png.filename().string()) << "</figcaption></figure>\n";
  html << "</section>\n";
  return html.str();
}

const char* kStyle =
    "body{font-family:sans-serif;margin:1em 2em;}"
    ".walk{display:flex;flex-wrap:wrap;gap:1em;}"
    ".run{border:1px solid #ccc;padding:0.5em 1em;max-width:660px;}"
    "img{max-width:640px;}figure{margin:0.5em 0;}";

}  // namespace

void write_report_html(const fs::path& dir, const std::vector<HtmlRun>& runs) {
  // A walk: the same scenario and seed, so its runs hear and see the same path.
  std::map<std::pair<std::string, std::uint64_t>, std::vector<const HtmlRun*>> walks;
  for (const HtmlRun& r : runs) walks[{r.scenario, r.seed}].push_back(&r);
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>sonomap report: "
       << xml_escape(dir.filename().string()) << "</title>\n<style>" << kStyle << "</style></head>\n<body>\n"
       << "<h1>sonomap report: " << xml_escape(dir.filename().string()) << "</h1>\n"
       << "<p>" << runs.size() << " runs. Tables and numbers: <a href=\"report.md\">report.md</a>, "
       << "<a href=\"rollup.csv\">rollup.csv</a>.</p>\n";
  for (const auto& [walk, list] : walks) {
    html << "<h2>" << xml_escape(walk.first) << ", seed " << walk.second << "</h2>\n<div class=\"walk\">\n";
    for (const HtmlRun* r : list) html << run_section(dir, *r);
    html << "</div>\n";
  }
  const std::vector<fs::path> plots = files(dir, "plots", ".png");
  if (!plots.empty()) html << "<h2>Plots</h2>\n";
  for (const fs::path& png : plots)
    html << "<figure><img src=\"" << url(png) << "\" alt=\"" << xml_escape(png.filename().string())
         << "\"></figure>\n";
  html << "</body></html>\n";
  write_text_file(dir / "report.html", html.str());
}

}  // namespace sonomap::harness
