// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/report.hpp"

#include "harness/report/claims.hpp"
#include "harness/formats/run_summary.hpp"

#include "harness/report/pictures.hpp"
#include "harness/report/report_html.hpp"
#include "harness/report/rollup.hpp"
#include "harness/report/stats_report.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

struct RunRecord {
  std::string id;
  fs::path dir;
  RunSummary summary;
  RunTimings timings;
  std::vector<std::pair<std::string, std::string>> metrics;  // rollup.csv's names and cells
  std::string scenario, variant, mapper;
  double voxel = NAN;
};

std::string tag(const RunSummary& summary, const char* key, const std::string& fallback) {
  const auto it = summary.tags.find(key);
  return it == summary.tags.end() ? fallback : it->second;
}

RunRecord read_run(const fs::path& dir) {
  RunRecord r;
  r.id = dir.filename().string();
  r.dir = dir;
  r.summary = read_run_summary(dir);
  r.timings = read_run_timings(dir);
  r.metrics = summary_metrics(r.summary);
  r.mapper = r.summary.config.mapper;
  r.scenario = tag(r.summary, "scenario", r.summary.scenario_name);
  r.variant = tag(r.summary, "variant", r.mapper);
  const auto& mc = r.summary.config.mapper_config;
  for (const char* key : {"global_voxel", "voxel"})
    if (const auto it = mc.find(key); it != mc.end()) r.voxel = std::stod(it->second);
  return r;
}

std::vector<RunRecord> read_runs(const fs::path& dir) {
  std::vector<RunRecord> runs;
  const fs::path runs_dir = dir / "runs";
  if (!fs::is_directory(runs_dir)) return runs;
  for (const auto& entry : fs::directory_iterator(runs_dir))
    if (entry.is_directory() && fs::is_regular_file(entry.path() / "summary.json"))
      runs.push_back(read_run(entry.path()));
  std::sort(runs.begin(), runs.end(), [](const RunRecord& a, const RunRecord& b) { return a.id < b.id; });
  return runs;
}

// A metric of rollup.csv as its cell text ("" when undefined or absent).
const std::string& metric(const RunRecord& r, const std::string& name) {
  static const std::string none;
  for (const auto& [key, cell] : r.metrics)
    if (key == name) return cell;
  return none;
}

std::string value(const RunRecord& r, const char* raster, const char* which, const char* name) {
  return metric(r, fmt::format("{}_{}_{}", raster, which, name));
}

// Table cells: coverage in percent, RMSE in metres, "-" when undefined.
std::string coverage_cell(const RunRecord& r, const char* raster, const char* which) {
  const std::string v = value(r, raster, which, "coverage");
  return v.empty() ? std::string("-") : fmt::format("{:.1f}%", 100 * std::stod(v));
}
std::string rmse_cell(const RunRecord& r, const char* raster, const char* which) {
  const std::string v = value(r, raster, which, "rmse");
  return v.empty() ? std::string("-") : fmt::format("{:.3f}", std::stod(v));
}

// "final / mean" of a table cell (coverage_cell or rmse_cell).
template <typename Cell>
std::string final_and_mean(const RunRecord& r, const char* raster, Cell cell) {
  return cell(r, raster, "final") + " / " + cell(r, raster, "mean");
}

// The EDF's bearing slip, `which` = final or mean; "-" when absent.
std::string slip(const RunRecord& r, const char* which, const char* name) {
  const std::string& v = metric(r, fmt::format("edf_slip_{}_{}", which, name));
  return v.empty() ? std::string("-") : v;
}

std::vector<std::string> stage_names(const std::vector<RunRecord>& runs) {
  std::set<std::string> names;
  for (const auto& r : runs)
    for (const auto& [name, timing] : r.timings) names.insert(name);
  return {names.begin(), names.end()};
}

std::string median(const RunRecord& r, const std::string& stage) {
  const auto it = r.timings.find(stage);
  return it == r.timings.end() ? "" : fmt::format("{:.3f}", it->second.median_ms);
}

// Whether a column of a run's frames.csv has a value in any row (a scored program's cylinder,
// or recorded data's metrics, may have none).
bool has_values(const RunRecord& r, const std::string& column) {
  std::ifstream in(r.dir / "frames.csv");
  std::string line;
  if (!std::getline(in, line)) return false;
  const RollupTable header = RollupTable::parse(line);
  const int c = header.column(column);
  while (c >= 0 && std::getline(in, line))
    if (!header.cell(split_csv_line(line), c).empty()) return true;
  return false;
}

// Per scenario and raster: one line per run over frames, for a column of frames.csv (runs
// without a value in it left out; no picture when none has one).
void plot_over_frames(const fs::path& png, std::vector<const RunRecord*> runs,
                      const std::string& column, const std::string& title, const std::string& ylabel) {
  fs::remove(png);  // an earlier report's picture
  runs.erase(std::remove_if(runs.begin(), runs.end(), [&](const RunRecord* r) { return !has_values(*r, column); }),
             runs.end());
  if (runs.empty()) return;
  std::ostringstream gp;
  gp << "set terminal pngcairo size 1000,500 noenhanced font 'DejaVu Sans,11'\n"
     << "set output '" << png.string() << "'\nset title '" << title << "'\n"
     << "set xlabel 'frame'\nset ylabel '" << ylabel << "'\nset key outside right\nset grid\n"
     << "set datafile separator ','\nplot ";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const fs::path csv = runs[i]->dir / "frames.csv";
    gp << (i ? ", \\\n     " : "") << "'" << csv.string() << "' using 'frame':'" << column
       << "' with lines lw 2 title '" << runs[i]->variant << " s" << runs[i]->summary.seed << "'";
  }
  gp << "\n";
  draw_with_gnuplot(png, gp.str());
}

// Median stage times against voxel size, one line per (mapper, stage).
void plot_time_vs_voxel(const fs::path& png, const std::vector<const RunRecord*>& runs,
                        const std::vector<std::string>& stages) {
  std::ostringstream gp;
  gp << "set terminal pngcairo size 1000,500 noenhanced font 'DejaVu Sans,11'\n"
     << "set output '" << png.string() << "'\nset title 'median time per frame vs voxel size'\n"
     << "set xlabel 'voxel (m)'\nset ylabel 'ms per frame'\nset key outside right\nset grid\n"
     << "set logscale y\n";
  std::map<std::string, std::vector<const RunRecord*>> by_mapper;
  for (const RunRecord* r : runs)
    if (std::isfinite(r->voxel)) by_mapper[r->mapper].push_back(r);
  std::vector<std::string> plots;
  int block = 0;
  for (auto& [mapper, list] : by_mapper) {
    std::sort(list.begin(), list.end(), [](auto* a, auto* b) { return a->voxel < b->voxel; });
    for (const std::string& stage : stages) {
      std::string data;
      for (const RunRecord* r : list)
        if (const auto it = r->timings.find(stage); it != r->timings.end())
          data += fmt::format("{} {}\n", r->voxel, it->second.median_ms);
      if (data.empty()) continue;
      gp << "$d" << block << " << EOD\n" << data << "EOD\n";
      plots.push_back(fmt::format("$d{} using 1:2 with linespoints lw 2 title '{} {}'", block, mapper, stage));
      ++block;
    }
  }
  if (plots.empty()) return;
  gp << "plot ";
  for (std::size_t i = 0; i < plots.size(); ++i) gp << (i ? ", \\\n     " : "") << plots[i];
  gp << "\n";
  draw_with_gnuplot(png, gp.str());
}

// rollup.csv: one row per run.
std::string rollup_csv(const std::vector<RunRecord>& runs, const std::vector<std::string>& stages) {
  std::ostringstream csv;
  csv << "run,scenario,variant,mapper,voxel,seed,frames";
  for (const auto& [name, unused] : summary_metrics(RunSummary{})) csv << ',' << name;
  for (const auto& s : stages) csv << ",median_" << s << "_ms";
  csv << '\n';
  for (const RunRecord& r : runs) {
    csv << r.id << ',' << r.scenario << ',' << r.variant << ',' << r.mapper << ','
        << (std::isfinite(r.voxel) ? fmt::format("{}", r.voxel) : "") << ',' << r.summary.seed << ','
        << r.summary.config.frames;
    for (const auto& [name, cell] : r.metrics) csv << ',' << cell;
    for (const auto& s : stages) csv << ',' << median(r, s);
    csv << '\n';
  }
  return csv.str();
}

// A scenario's table of runs: coverage, RMSE and ghosts of both rasters, integrate time.
std::string runs_table(const std::vector<const RunRecord*>& list) {
  std::ostringstream md;
  md << "| run | mapper | voxel | circle cov. (final / mean) | circle RMSE (final / mean) | "
        "circle ghosts (final) | cylinder cov. (final / mean) | cylinder RMSE (final / mean) | "
        "cylinder ghosts (final) | integrate ms (median) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const RunRecord* r : list)
    md << "| " << r->id << " | " << r->mapper << " | "
       << (std::isfinite(r->voxel) ? fmt::format("{}", r->voxel) : "-") << " | "
       << final_and_mean(*r, "circle", coverage_cell) << " | " << final_and_mean(*r, "circle", rmse_cell)
       << " | " << value(*r, "circle", "final", "ghosts") << " | " << final_and_mean(*r, "cylinder", coverage_cell)
       << " | " << final_and_mean(*r, "cylinder", rmse_cell) << " | " << value(*r, "cylinder", "final", "ghosts")
       << " | " << median(*r, "integrate") << " |\n";
  return md.str() + "\n";
}

// The paper's "Compare to EDF": the field's direction to the closest surface against each
// bin's bearing, and the circle the EDF gives by sphere tracing, beside the map's circle.
std::string edf_table(const std::vector<const RunRecord*>& list) {
  std::ostringstream md;
  md << "### Compare to EDF\n\n"
     << "Bearing slip: angle between the direction to the closest surface (the EDF's "
        "-gradient at the bin's point on the sample circle) and the bin's ray, degrees, over "
        "the bins where the field is observed. EDF circle: ranges sphere-traced in the field "
        "along each bin's ray at the sensor's height.\n\n"
     << "| run | mapper | slip median / p90 (final) | slip median / p90 (mean) | "
        "EDF circle cov. (final / mean) | EDF circle RMSE (final / mean) | "
        "map circle cov. / RMSE (final) |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const RunRecord* r : list)
    md << "| " << r->id << " | " << r->mapper << " | " << slip(*r, "final", "median_deg") << " / "
       << slip(*r, "final", "p90_deg") << " | " << slip(*r, "mean", "median_deg") << " / "
       << slip(*r, "mean", "p90_deg") << " | " << final_and_mean(*r, "edf_circle", coverage_cell) << " | "
       << final_and_mean(*r, "edf_circle", rmse_cell) << " | " << coverage_cell(*r, "circle", "final")
       << " / " << rmse_cell(*r, "circle", "final") << " |\n";
  return md.str() + "\n";
}

// Per run and moving object: when its old place was first seen empty, how many frames its
// ghosts in the circle took to clear after that, and the ghost bins left at the end.
std::string moved_objects_table(const std::vector<const RunRecord*>& list) {
  std::ostringstream md;
  md << "### Moved objects\n\n"
     << "Ghost clearing (docs/conventions.md): frames from the moment a part of the object's old "
        "place is seen empty until no circle bin reads it, the worst over its old places; "
        "\"never\" when bins still read a seen-empty old place at the last frame.\n\n"
     << "| run | mapper | object | seen empty at frame | clearing frames | ghost bins left (seen / unseen) "
        "| most ghost bins | frames with ghosts |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  const auto frame_cell = [](const std::optional<int>& v) { return v ? std::to_string(*v) : std::string("-"); };
  for (const RunRecord* r : list)
    for (const eval::MovedObjectClearing& m : r->summary.moved_objects)
      md << "| " << r->id << " | " << r->mapper << " | " << m.name << " | " << frame_cell(m.seen_empty_frame)
         << " | " << (m.cleared() ? std::to_string(*m.clearing_frames) : m.seen_empty_frame ? "never" : "-")
         << " | " << m.ghost_bins_at_end << " / " << m.unseen_ghost_bins_at_end << " | " << m.max_ghost_bins
         << " | " << m.ghost_frames << " |\n";
  return md.str() + "\n";
}

// A scenario's plots over frames and of time against voxel size, drawn into dir/plots.
std::string scenario_plots(const fs::path& dir, const std::string& scenario,
                           const std::vector<const RunRecord*>& list, const std::vector<std::string>& stages) {
  const std::vector<std::pair<std::string, std::string>> series = {
      {"circle_coverage", "circle coverage"}, {"cylinder_coverage", "cylinder coverage"},
      {"circle_rmse", "circle RMSE (m)"},     {"cylinder_rmse", "cylinder RMSE (m)"},
      {"circle_rmse_off_edges", "circle RMSE off silhouette edges (m)"},
      {"cylinder_rmse_off_edges", "cylinder RMSE off silhouette edges (m)"},
      {"circle_ghosts", "circle ghost bins"}, {"cylinder_ghosts", "cylinder ghost cells"},
      {"circle_moved_ghosts", "circle ghost bins in places moved objects left"}};
  std::ostringstream md;
  for (const auto& [column, label] : series) {
    const std::string name = scenario + "_" + column + ".png";
    plot_over_frames(dir / "plots" / name, list, column, scenario + ": " + label + " over frames", label);
    if (fs::exists(dir / "plots" / name)) md << "![" << label << "](plots/" << name << ")\n\n";
  }
  const std::string tname = scenario + "_time_vs_voxel.png";
  plot_time_vs_voxel(dir / "plots" / tname, list, stages);
  if (fs::exists(dir / "plots" / tname)) md << "![time vs voxel](plots/" << tname << ")\n\n";
  return md.str();
}

std::string report_intro(const fs::path& dir, std::size_t runs) {
  return "# sonomap report: " + dir.filename().string() + "\n\n" + std::to_string(runs) +
         " runs, rolled up from `" + (dir / "runs").string() +
         "` (`rollup.csv` has every number below). Coverage: known bins also occupied in the ground "
         "truth / occupied truth bins; RMSE over bins known in both (m); ghosts: bins known in "
         "the estimate but empty in the truth or more than the tolerance closer "
         "(docs/conventions.md).\n\n";
}

}  // namespace

ReportOutcome build_report(const fs::path& dir, bool quiet, const fs::path& junit) {
  const std::vector<RunRecord> runs = read_runs(dir);
  if (runs.empty()) throw InputError(dir.string() + ": no finished run under " + (dir / "runs").string());
  const std::vector<std::string> stages = stage_names(runs);
  const std::string csv = rollup_csv(runs, stages);
  write_text_file(dir / "rollup.csv", csv);

  fs::create_directories(dir / "plots");
  std::map<std::string, std::vector<const RunRecord*>> by_scenario;
  for (const RunRecord& r : runs) by_scenario[r.scenario].push_back(&r);
  std::ostringstream md;
  md << report_intro(dir, runs.size());
  const RollupTable rollup = RollupTable::parse(csv);
  const std::vector<Claim> claims = read_claims(dir), gates = read_claims(dir, "gates.json");
  ReportOutcome outcome{static_cast<int>(runs.size()), 0};
  md << gates_section(gates, rollup, outcome.failed_gates) << claims_section(claims, rollup)
     << stats_section(dir, rollup);
  if (!junit.empty()) write_text_file(junit, junit_xml(claims, gates, rollup));
  for (const auto& [scenario, list] : by_scenario) {
    md << "## " << scenario << "\n\n" << runs_table(list);
    if (std::any_of(list.begin(), list.end(), [](const RunRecord* r) { return r->summary.edf.has_value(); }))
      md << edf_table(list);
    if (std::any_of(list.begin(), list.end(), [](const RunRecord* r) { return !r->summary.moved_objects.empty(); }))
      md << moved_objects_table(list);
    md << scenario_plots(dir, scenario, list, stages);
  }
  write_text_file(dir / "report.md", md.str());
  std::vector<HtmlRun> html_runs;
  for (const RunRecord& r : runs) html_runs.push_back({r.id, r.scenario, r.variant, r.mapper, r.summary.seed});
  write_report_html(dir, html_runs);
  if (!quiet)
    std::printf("report: %zu runs -> %s, %s, %s, %s\n", runs.size(), (dir / "rollup.csv").c_str(),
                (dir / "report.md").c_str(), (dir / "report.html").c_str(), (dir / "plots").c_str());
  if (outcome.failed_gates > 0)
    std::fprintf(stderr, "report: %d of %zu gates fail (see %s)\n", outcome.failed_gates, gates.size(),
                 (dir / "report.md").c_str());
  return outcome;
}

void add_report_command(CLI::App& app, const GlobalOptions& global) {
  auto dir = std::make_shared<fs::path>();
  auto junit = std::make_shared<fs::path>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Roll up the finished runs under DIR/runs into rollup.csv, rollup_stats.csv, "
                "pairs.csv, plots and report.md; exit status 1 when a gate fails");
  cmd->add_option("dir", *dir, "Directory written by `sonomap compare` (also with --emit-jobs)")
      ->required();
  cmd->add_option("--junit", *junit, "Also write JUnit XML: one test case per gate and claim");
  cmd->callback([dir, junit, &global] {
    // It writes its roll-ups and plots/ there: into a folder sonomap made, or one that has
    // none of them yet (runs/ gathered by hand), which it then marks as its own.
    if (!is_sonomap_result(*dir)) {
      if (!fs::is_directory(*dir / "runs"))
        throw InputError(dir->string() + " is not a sonomap result and holds no runs/");
      for (const char* name : {"rollup.csv", "rollup_stats.csv", "pairs.csv", "report.md", "report.html", "plots"})
        if (fs::exists(*dir / name))
          throw InputError((*dir / name).string() + " exists and was not written by sonomap; "
                           "report writes only into a folder `sonomap compare` made");
      mark_as_result(*dir, "report");
    }
    if (build_report(*dir, global.quiet, *junit).failed_gates > 0) throw CLI::RuntimeError(kExitFailure);
  });
}

}  // namespace sonomap::harness
