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

std::vector<Claim> read_claims(const fs::path& dir, const std::string& file_name) {
  const fs::path file = dir / file_name;
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

ClaimCheck check_claim(const Claim& c, const RollupTable& rollup) {
  const int scenario = rollup.column("scenario"), variant = rollup.column("variant");
  const int metric = rollup.column(c.metric);
  // Mean of the metric over the rows of (scenario, variant); NaN when there is none.
  auto figure = [&](const std::string& variant_id) {
    double sum = 0.0;
    int n = 0;
    for (const auto& row : rollup.rows) {
      const double v = rollup.number(row, metric);
      if (rollup.cell(row, scenario) != c.scenario || rollup.cell(row, variant) != variant_id || !std::isfinite(v))
        continue;
      sum += v;
      ++n;
    }
    return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
  };
  ClaimCheck check;
  check.ours = "not measured";
  check.check = c.op + ' ' + (c.versus.empty() ? fmt::format("{:g}", c.value) : fmt::format("{:g} x {}", c.value, c.versus));
  if (metric < 0) return check;
  const double mine = figure(c.variant);
  const double other = c.versus.empty() ? 1.0 : figure(c.versus);
  if (!std::isfinite(mine) || !std::isfinite(other)) return check;
  check.measured = true;
  check.ours = fmt::format("{:.4g}", mine);
  if (!c.versus.empty()) check.ours += fmt::format(" ({}: {:.4g})", c.versus, other);
  check.holds = holds(mine, c.op, c.value * other);
  return check;
}

std::string claims_section(const std::vector<Claim>& claims, const RollupTable& rollup) {
  if (claims.empty()) return {};
  std::ostringstream md;
  md << "## Against the paper\n\n"
     << "Each of the paper's figures that this sweep reproduces, checked against our runs (mean "
        "over seeds). A claim that differs is not a test failure: it is a finding, and its note "
        "says why.\n\n"
     << "| claim | paper | ours | check | verdict | note |\n|---|---|---|---|---|---|\n";
  int agree = 0, differ = 0;
  for (const Claim& c : claims) {
    const ClaimCheck check = check_claim(c, rollup);
    std::string verdict = "-";
    if (check.measured) {
      verdict = check.holds ? "agrees" : "**differs**";
      ++(check.holds ? agree : differ);
    }
    md << "| " << c.text << " (" << c.scenario << " / " << c.variant << ", `" << c.metric
       << "`) | " << c.paper << " | " << check.ours << " | " << check.check << " | " << verdict
       << " | " << c.note << " |\n";
  }
  md << "\n" << agree << " agree, " << differ << " differ, "
     << (claims.size() - agree - differ) << " not measured.\n\n";
  return md.str();
}

std::string gates_section(const std::vector<Claim>& gates, const RollupTable& rollup, int& failed) {
  failed = 0;
  if (gates.empty()) return {};
  std::ostringstream md;
  md << "## Gates\n\nThe sweep's CI gates (mean over seeds); a gate that fails or cannot be "
        "measured makes `report` and `compare` exit with status 1.\n\n"
     << "| gate | scenario / variant | metric | ours | check | result |\n|---|---|---|---|---|---|\n";
  for (const Claim& g : gates) {
    const ClaimCheck check = check_claim(g, rollup);
    const bool pass = check.measured && check.holds;
    if (!pass) ++failed;
    md << "| " << g.text << " | " << g.scenario << " / " << g.variant << " | `" << g.metric << "` | "
       << check.ours << " | " << check.check << " | " << (pass ? "pass" : "**FAIL**") << " |\n";
  }
  md << "\n" << gates.size() - failed << " of " << gates.size() << " gates pass.\n\n";
  return md.str();
}

std::string xml_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

namespace {

// One <testsuite>: a gate fails when it does not hold or is not measured; a claim that
// differs or is not measured is skipped (a finding, not a failure).
std::string junit_suite(const std::string& name, const std::vector<Claim>& checks,
                        const RollupTable& rollup, bool gates) {
  std::ostringstream cases;
  int failures = 0, skipped = 0;
  for (const Claim& c : checks) {
    const ClaimCheck check = check_claim(c, rollup);
    const std::string what = fmt::format("{} / {}: {} = {}, expected {}", c.scenario, c.variant,
                                         c.metric, check.ours, check.check);
    cases << "    <testcase classname=\"sonomap." << name << '.' << xml_escape(c.scenario) << '.'
          << xml_escape(c.variant) << "\" name=\"" << xml_escape(c.text) << "\">\n";
    if (!(check.measured && check.holds) && gates) {
      cases << "      <failure message=\"" << xml_escape(what) << "\"/>\n";
      ++failures;
    } else if (!(check.measured && check.holds)) {
      const std::string why = check.measured ? "differs from the paper: " : "";
      cases << "      <skipped message=\"" << xml_escape(why + what) << "\"/>\n";
      ++skipped;
    }
    cases << "      <system-out>" << xml_escape(what) << "</system-out>\n    </testcase>\n";
  }
  return fmt::format("  <testsuite name=\"sonomap {}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\">\n",
                     name, checks.size(), failures, skipped) + cases.str() + "  </testsuite>\n";
}

}  // namespace

std::string junit_xml(const std::vector<Claim>& claims, const std::vector<Claim>& gates,
                      const RollupTable& rollup) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"sonomap\">\n" +
         junit_suite("gates", gates, rollup, true) + junit_suite("claims", claims, rollup, false) +
         "</testsuites>\n";
}

}  // namespace sonomap::harness
