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

bool is_claim_operator(const std::string& op);

nlohmann::json claims_to_json(const std::vector<Claim>& claims);
// Reads DIR/claims.json; none if the file does not exist. Throws InputError if it is malformed.
std::vector<Claim> read_claims(const std::filesystem::path& dir);

// The report's "Against the paper" section: each claim checked against the roll-up
// (rollup.csv's text): our figure (mean over the matching runs), the check and its verdict.
std::string claims_section(const std::vector<Claim>& claims, const std::string& rollup_csv);

}  // namespace sonomap::harness
