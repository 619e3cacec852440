// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/stats_report.hpp"

#include "harness/report/pictures.hpp"
#include "harness/report/stats.hpp"
#include "harness/support/output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// The metrics report.md shows; the CSVs have every one.
const std::vector<std::string> kHeadline = {"circle_mean_coverage", "circle_mean_rmse", "circle_final_ghosts",
                                            "cylinder_mean_coverage", "cylinder_mean_rmse"};

// The roll-up's runs by scenario, variant (in order of appearance) and seed.
struct Runs {
  std::vector<std::string> scenarios, variants;
  std::map<std::string, std::map<std::string, std::map<std::string, const std::vector<std::string>*>>> by;
  explicit Runs(const RollupTable& t) {
    const int s = t.column("scenario"), v = t.column("variant"), seed = t.column("seed");
    for (const auto& row : t.rows) {
      const std::string& sc = t.cell(row, s);
      const std::string& va = t.cell(row, v);
      if (std::find(scenarios.begin(), scenarios.end(), sc) == scenarios.end()) scenarios.push_back(sc);
      if (std::find(variants.begin(), variants.end(), va) == variants.end()) variants.push_back(va);
      by[sc][va][t.cell(row, seed)] = &row;
    }
  }
};

std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : ""; }

std::string stats_csv_cells(const SampleStats& s) {
  return fmt::format("{},{},{},{},{}", s.n, num(s.mean), num(s.sd), num(s.ci_low), num(s.ci_high));
}

// The differences candidate - baseline of `metric` over the seeds both ran, in the scenarios given.
SampleStats paired(const Runs& runs, const RollupTable& t, const std::vector<std::string>& scenarios,
                   const std::string& baseline, const std::string& candidate, int metric) {
  std::vector<double> d;
  for (const std::string& sc : scenarios) {
    const auto scenario = runs.by.find(sc);
    const auto a = scenario->second.find(baseline), b = scenario->second.find(candidate);
    if (a == scenario->second.end() || b == scenario->second.end()) continue;
    for (const auto& [seed, row] : a->second) {
      const auto other = b->second.find(seed);
      if (other == b->second.end()) continue;
      const double diff = t.number(*other->second, metric) - t.number(*row, metric);
      if (std::isfinite(diff)) d.push_back(diff);
    }
  }
  return describe(d);
}

SampleStats group_stats(const Runs& runs, const RollupTable& t, const std::string& sc, const std::string& va,
                        int metric) {
  std::vector<double> sample;
  const auto& scenario = runs.by.at(sc);
  if (const auto it = scenario.find(va); it != scenario.end())
    for (const auto& [seed, row] : it->second)
      if (const double v = t.number(*row, metric); std::isfinite(v)) sample.push_back(v);
  return describe(sample);
}

// Mean with its 95% interval as error bars, one point per variant.
void plot_with_error_bars(const fs::path& png, const std::string& title,
                          const std::vector<std::pair<std::string, SampleStats>>& points) {
  fs::remove(png);  // an earlier report's picture
  std::ostringstream gp, data;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SampleStats& s = points[i].second;
    if (!std::isfinite(s.mean)) continue;
    const double lo = std::isfinite(s.ci_low) ? s.ci_low : s.mean, hi = std::isfinite(s.ci_high) ? s.ci_high : s.mean;
    data << i << ' ' << s.mean << ' ' << lo << ' ' << hi << " \"" << points[i].first << "\"\n";
  }
  if (data.str().empty()) return;
  gp << "set terminal pngcairo size 800,450 noenhanced font 'DejaVu Sans,11'\n"
     << "set output '" << png.string() << "'\nset title '" << title << "'\nset grid\nset offsets 0.5, 0.5, 0, 0\n"
     << "set xtics rotate by -30\nset ylabel 'mean over seeds, 95% interval'\n$d << EOD\n" << data.str()
     << "EOD\nplot $d using 1:2:3:4:xtic(5) with yerrorbars lw 2 pt 7 notitle\n";
  draw_with_gnuplot(png, gp.str());
}

// One scenario's variants: every metric into rollup_stats.csv, the headline ones into a
// markdown table and a plot with error bars each.
std::string group_section(const fs::path& dir, const Runs& runs, const RollupTable& t,
                          const std::string& sc, std::ostringstream& csv) {
  std::ostringstream md;
  md << "### " << sc << "\n\n| variant |";
  for (const auto& m : kHeadline) md << ' ' << m << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < kHeadline.size(); ++i) md << "---|";
  md << '\n';
  for (const std::string& va : runs.variants) {
    if (!runs.by.at(sc).count(va)) continue;
    for (const std::string& m : t.metrics())
      csv << sc << ',' << va << ',' << m << ',' << stats_csv_cells(group_stats(runs, t, sc, va, t.column(m))) << '\n';
    md << "| " << va << " |";
    for (const auto& m : kHeadline) {
      const SampleStats s = group_stats(runs, t, sc, va, t.column(m));
      if (s.n == 0) md << " - |";
      else if (s.n == 1) md << ' ' << num(s.mean) << " (1 seed) |";
      else md << fmt::format(" {:.4g} ± {:.2g} ({} seeds) |", s.mean, s.ci_high - s.mean, s.n);
    }
    md << '\n';
  }
  md << '\n';
  for (const std::string& m : {std::string("circle_mean_coverage"), std::string("circle_mean_rmse")}) {
    std::vector<std::pair<std::string, SampleStats>> points;
    for (const std::string& va : runs.variants)
      if (runs.by.at(sc).count(va)) points.push_back({va, group_stats(runs, t, sc, va, t.column(m))});
    const std::string name = sc + "_stats_" + m + ".png";
    plot_with_error_bars(dir / "plots" / name, sc + ": " + m + " per variant", points);
    if (fs::exists(dir / "plots" / name)) md << "![" << m << " per variant](plots/" << name << ")\n\n";
  }
  return md.str();
}

// Every pair of variants in `scenarios`: every metric into pairs.csv, the headline ones into
// a markdown table.
std::string pairs_section(const Runs& runs, const RollupTable& t, const std::string& scope,
                          const std::vector<std::string>& scenarios, std::ostringstream& csv) {
  const std::string unit = scenarios.size() > 1 ? "runs" : "seeds";
  std::ostringstream md;
  for (std::size_t i = 0; i < runs.variants.size(); ++i)
    for (std::size_t j = i + 1; j < runs.variants.size(); ++j) {
      const std::string &base = runs.variants[i], &cand = runs.variants[j];
      for (const std::string& m : t.metrics()) {
        const SampleStats d = paired(runs, t, scenarios, base, cand, t.column(m));
        if (d.n == 0) continue;
        const std::string verdict = paired_verdict(d, m, unit);
        csv << scope << ',' << base << ',' << cand << ',' << m << ',' << stats_csv_cells(d) << ',' << verdict << '\n';
        if (std::find(kHeadline.begin(), kHeadline.end(), m) == kHeadline.end()) continue;
        md << "| " << cand << " vs " << base << " | " << m << " | " << d.n << " | " << num(d.mean) << " ["
           << num(d.ci_low) << ", " << num(d.ci_high) << "] | " << verdict << " |\n";
      }
    }
  if (md.str().empty()) return {};
  return "### Pairs: " + scope + "\n\n| candidate vs baseline | metric | n | difference [95% interval] | verdict |\n"
         "|---|---|---|---|---|\n" + md.str() + "\n";
}

}  // namespace

std::string stats_section(const fs::path& dir, const RollupTable& t) {
  const Runs runs(t);
  std::ostringstream stats_csv, pairs_csv, md;
  stats_csv << "scenario,variant,metric,n,mean,sd,ci95_low,ci95_high\n";
  pairs_csv << "scenario,baseline,candidate,metric,n,mean_difference,sd,ci95_low,ci95_high,verdict\n";
  md << "## Statistics over seeds\n\nMean ± the half width of the 95% Student t interval over seeds, "
        "per scenario and variant (`rollup_stats.csv` has every metric with n, standard deviation "
        "and interval). Pairs: the difference candidate - baseline over the same seeds, with its "
        "95% interval (`pairs.csv` has every metric); \"better\" or \"worse\" only when the "
        "interval excludes zero.\n\n";
  fs::create_directories(dir / "plots");
  for (const std::string& sc : runs.scenarios) md << group_section(dir, runs, t, sc, stats_csv);
  for (const std::string& sc : runs.scenarios) md << pairs_section(runs, t, sc, {sc}, pairs_csv);
  if (runs.scenarios.size() > 1) md << pairs_section(runs, t, "all", runs.scenarios, pairs_csv);
  write_text_file(dir / "rollup_stats.csv", stats_csv.str());
  write_text_file(dir / "pairs.csv", pairs_csv.str());
  return md.str();
}

}  // namespace sonomap::harness
