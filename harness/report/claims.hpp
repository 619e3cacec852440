// SPDX-License-Identifier: GPL-3.0-or-later
// The paper's figures as checkable claims. A sweep file may list them; `compare` stores them
// beside the runs (claims.json) and `report` checks each against the roll-up, so the report
// says, figure by figure, where our numbers agree with the paper's and where they differ.
//
//   claims:
//     - text: "the map's circle reaches full coverage at 5 cm"
//       scenario: room          # a scenario id of the sweep
//       variant: gpdf_5cm       # a variant id of the sweep (mean over its seeds)
//       metric: circle_final_coverage   # a rollup.csv column
//       op: ">="                # >=, <=, >, <
//       value: 0.99
//       paper: "100%"           # the paper's own figure, as it states it
//       versus: depth_only      # optional: compare with value x this variant's figure
//       note: "why a difference is expected, if it is"
#pragma once

#include "harness/report/rollup.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace sonomap::harness {

struct Claim {
  std::string text;
  std::string scenario;
  std::string variant;
  std::string metric;
  std::string op;  // ">=", "<=", ">" or "<"
  double value = 0.0;
  std::string versus;  // empty: compare with value itself
  std::string paper;
  std::string note;
};

// CI gates (compare.hpp `gates:`) are claims that must hold: the same fields (text optional,
// no paper or note), checked the same way; a gate that fails or cannot be measured fails the
// report (exit status 1).

bool is_claim_operator(const std::string& op);

nlohmann::json claims_to_json(const std::vector<Claim>& claims);
// Reads DIR/<file_name>; none if the file does not exist. Throws InputError if it is malformed.
std::vector<Claim> read_claims(const std::filesystem::path& dir, const std::string& file_name = "claims.json");

// One claim checked against the roll-up: our figure is the mean of the metric over the runs of
// (scenario, variant); with `versus`, the bound is value x that variant's mean.
struct ClaimCheck {
  bool measured = false;  // both figures exist
  bool holds = false;
  std::string ours;   // "0.93", or "0.93 (depth: 0.4)", or "not measured"
  std::string check;  // ">= 0.99" or "< 0.5 x depth"
};
ClaimCheck check_claim(const Claim& claim, const RollupTable& rollup);

// The report's "Against the paper" section: each claim, our figure, the check and its verdict.
std::string claims_section(const std::vector<Claim>& claims, const RollupTable& rollup);

// The report's "Gates" section; `failed` counts the gates that fail or are not measured.
std::string gates_section(const std::vector<Claim>& gates, const RollupTable& rollup, int& failed);

// Text with &, <, >, " and ' as XML (and HTML) entities.
std::string xml_escape(const std::string& text);

// JUnit XML: a test suite of gates (failure when one fails or is not measured) and one of
// claims (a claim that differs from the paper is a finding, reported as skipped, not failed).
std::string junit_xml(const std::vector<Claim>& claims, const std::vector<Claim>& gates,
                      const RollupTable& rollup);

}  // namespace sonomap::harness
