// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap diff RESULT_A RESULT_B [--tolerance METRIC=VALUE ...]`: "did my change make it
// worse?" Prints every metric of two result directories (run or score) side by side with the
// change B - A and which way it went; exit status 1 when a metric given a tolerance got worse by
// more than it (or lost its value), 0 otherwise.
#include "harness/app/cli.hpp"
#include "harness/formats/run_summary.hpp"
#include "harness/report/rollup.hpp"
#include "harness/report/stats.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/fields.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// "metric=value" -> metric: value, checked against the metric names.
std::map<std::string, double> parse_tolerances(const std::vector<std::string>& given,
                                               const std::vector<std::pair<std::string, std::string>>& metrics) {
  std::map<std::string, double> out;
  for (const std::string& t : given) {
    const auto eq = t.find('=');
    const std::string name = t.substr(0, eq);
    bool known = false;
    for (const auto& m : metrics) known = known || m.first == name;
    if (eq == std::string::npos || !known)
      throw InputError("--tolerance " + t + ": expected METRIC=VALUE with a metric of summary.json's "
                       "rollup names (e.g. circle_mean_rmse=0.01)");
    double v = 0.0;
    if (!parse_number(t.substr(eq + 1), v) || v < 0.0)
      throw InputError("--tolerance " + t + ": the tolerance must be a finite number >= 0");
    out[name] = v;
  }
  return out;
}

// A metric's cell as a number; NaN when empty (undefined).
double cell_number(const std::string& text) {
  double v = NAN;
  return parse_number(text, v) ? v : NAN;
}

// The change's direction in words, and whether it breaks its tolerance.
std::pair<std::string, bool> judge(const std::string& metric, double a, double b, const double* tolerance) {
  if (!std::isfinite(a) && !std::isfinite(b)) return {"", false};
  if (!std::isfinite(b)) return {"lost", tolerance != nullptr};
  if (!std::isfinite(a)) return {"new", false};
  const double change = b - a;
  const Better better = better_direction(metric);
  const double worsening = better == Better::higher ? -change : better == Better::lower ? change : std::abs(change);
  if (change == 0.0) return {"same", false};
  const std::string word = better == Better::unknown ? "changed" : worsening > 0 ? "worse" : "better";
  return {word, tolerance && worsening > *tolerance};
}

int run_diff(const fs::path& a_dir, const fs::path& b_dir, const std::vector<std::string>& tolerance_args) {
  const RunSummary a = read_run_summary(a_dir), b = read_run_summary(b_dir);
  const auto a_metrics = summary_metrics(a), b_metrics = summary_metrics(b);
  const std::map<std::string, double> tolerances = parse_tolerances(tolerance_args, a_metrics);
  if (const std::string ha = config_hash(a.config), hb = config_hash(b.config); ha != hb)
    std::printf("note: the two results differ in configuration (config_hash %s vs %s)\n", ha.c_str(),
                hb.c_str());
  std::printf("%-28s %12s %12s %12s  %s\n", "metric", "A", "B", "B - A", "");
  int failures = 0;
  for (std::size_t i = 0; i < a_metrics.size(); ++i) {
    const std::string& name = a_metrics[i].first;
    const double va = cell_number(a_metrics[i].second), vb = cell_number(b_metrics[i].second);
    const auto tol = tolerances.find(name);
    const auto [word, fails] = judge(name, va, vb, tol == tolerances.end() ? nullptr : &tol->second);
    if (word.empty()) continue;
    failures += fails;
    const std::string change = std::isfinite(va) && std::isfinite(vb) ? fmt::format("{:+.6g}", vb - va) : "";
    std::string verdict = word;
    if (tol != tolerances.end()) verdict += fmt::format(" (tolerance {:g}: {})", tol->second, fails ? "FAIL" : "ok");
    std::printf("%-28s %12s %12s %12s  %s\n", name.c_str(), a_metrics[i].second.c_str(), b_metrics[i].second.c_str(),
                change.c_str(), verdict.c_str());
  }
  if (failures > 0) std::printf("diff: %d metric(s) worse than their tolerance\n", failures);
  return failures > 0 ? kExitFailure : 0;
}

}  // namespace

void add_diff_command(CLI::App& app, const GlobalOptions&) {
  auto a = std::make_shared<fs::path>(), b = std::make_shared<fs::path>();
  auto tolerances = std::make_shared<std::vector<std::string>>();
  CLI::App* cmd = app.add_subcommand(
      "diff", "Metric changes between two result directories (run or score); exit status 1 when a "
              "metric given a tolerance got worse by more than it");
  cmd->add_option("result_a", *a, "The reference result directory (e.g. from main)")->required();
  cmd->add_option("result_b", *b, "The result directory to judge")->required();
  cmd->add_option("--tolerance", *tolerances,
                  "METRIC=VALUE: fail when METRIC (a rollup.csv name, e.g. circle_mean_rmse) gets "
                  "worse by more than VALUE (repeatable)");
  cmd->callback([a, b, tolerances] {
    if (const int status = run_diff(*a, *b, *tolerances); status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace sonomap::harness
