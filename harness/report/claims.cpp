// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/claims.hpp"

#include "harness/support/errors.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace sonomap::harness {
namespace fs = std::filesystem;

namespace {

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

bool holds(double ours, const std::string& op, double value) {
  if (op == ">=") return ours >= value;
  if (op == "<=") return ours <= value;
  if (op == ">") return ours > value;
  return ours < value;
}

}  // namespace

bool is_claim_operator(const std::string& op) {
  return op == ">=" || op == "<=" || op == ">" || op == "<";
}

nlohmann::json claims_to_json(const std::vector<Claim>& claims) {
  nlohmann::json out = nlohmann::json::array();
  for (const Claim& c : claims)
    out.push_back({{"text", c.text}, {"scenario", c.scenario}, {"variant", c.variant},
                   {"metric", c.metric}, {"op", c.op}, {"value", c.value}, {"versus", c.versus}, {"paper", c.paper},
                   {"note", c.note}});
  return out;
}

std::vector<Claim> read_claims(const fs::path& dir) {
  const fs::path file = dir / "claims.json";
  std::ifstream in(file);
  if (!in) return {};
  std::vector<Claim> claims;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& c : j) {
      Claim claim{c.at("text").get<std::string>(),   c.at("scenario").get<std::string>(),
                  c.at("variant").get<std::string>(), c.at("metric").get<std::string>(),
                  c.at("op").get<std::string>(),      c.at("value").get<double>(),
                  c.value("versus", std::string()),   c.value("paper", std::string()),
                  c.value("note", std::string())};
      if (!is_claim_operator(claim.op)) throw InputError(file.string() + ": unknown op '" + claim.op + "'");
      claims.push_back(std::move(claim));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": malformed claims: " + e.what());
  }
  return claims;
}

std::string claims_section(const std::vector<Claim>& claims, const std::string& rollup_csv) {
  if (claims.empty()) return {};
  std::istringstream in(rollup_csv);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split_csv_line(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i) column[header[i]] = i;
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line))
    if (!line.empty()) rows.push_back(split_csv_line(line));

  std::ostringstream md;
  md << "## Against the paper\n\n"
     << "Each of the paper's figures that this sweep reproduces, checked against our runs (mean "
        "over seeds). A claim that differs is not a test failure: it is a finding, and its note "
        "says why.\n\n"
     << "| claim | paper | ours | check | verdict | note |\n|---|---|---|---|---|---|\n";
  // Mean of `metric` over the rows of (scenario, variant); NaN when there is none.
  auto figure = [&](const std::string& scenario, const std::string& variant, const std::string& metric) {
    const auto col = column.find(metric);
    if (col == column.end() || !column.count("scenario") || !column.count("variant"))
      return std::numeric_limits<double>::quiet_NaN();
    double sum = 0.0;
    int n = 0;
    for (const auto& row : rows) {
      if (row.size() <= col->second || row[column["scenario"]] != scenario ||
          row[column["variant"]] != variant || row[col->second].empty())
        continue;
      sum += std::stod(row[col->second]);
      ++n;
    }
    return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
  };
  int agree = 0, differ = 0;
  for (const Claim& c : claims) {
    std::string ours = "not measured", verdict = "-";
    const double mine = figure(c.scenario, c.variant, c.metric);
    const double other = c.versus.empty() ? 1.0 : figure(c.scenario, c.versus, c.metric);
    if (std::isfinite(mine) && std::isfinite(other)) {
      ours = fmt::format("{:.4g}", mine);
      if (!c.versus.empty()) ours += fmt::format(" ({}: {:.4g})", c.versus, other);
      const bool ok = holds(mine, c.op, c.value * other);
      verdict = ok ? "agrees" : "**differs**";
      ++(ok ? agree : differ);
    }
    const std::string bound = c.versus.empty() ? fmt::format("{:g}", c.value)
                                               : fmt::format("{:g} x {}", c.value, c.versus);
    md << "| " << c.text << " (" << c.scenario << " / " << c.variant << ", `" << c.metric
       << "`) | " << c.paper << " | " << ours << " | " << c.op << ' ' << bound << " | " << verdict
       << " | " << c.note << " |\n";
  }
  md << "\n" << agree << " agree, " << differ << " differ, "
     << (claims.size() - agree - differ) << " not measured.\n\n";
  return md.str();
}

}  // namespace sonomap::harness
