// SPDX-License-Identifier: GPL-3.0-or-later
// The numeric keys of a scenario file (and of a sequence's camera.yaml), each declared once with
// its unit, physical bounds and meaning. The scenario reader checks every number against this
// table; docs/settings.md lists it (checked by a test).
#pragma once

#include "harness/support/fields.hpp"

#include <string>
#include <vector>

namespace sonomap::harness {

struct ScenarioKey {
  // The dotted key with list items as [] ("body.keyframes[].time"); a leading "*." matches any
  // key that ends so ("*.position": every position of a pose or keyframe).
  std::string pattern;
  bool whole = false;  // a whole number
  std::string unit;
  Range range;
  std::string doc;
};

const std::vector<ScenarioKey>& scenario_keys();

// The declaration that covers `key` (as errors name it: "static[2].pose.position[0]"), first
// match in table order; camera.yaml keys ("width") match their sensor.* declaration.
// Throws std::logic_error for a key nobody declared (a reader that forgot its bounds).
const ScenarioKey& scenario_key(const std::string& key);

// The table as markdown: | key | unit | range | meaning |.
std::string scenario_keys_markdown();

}  // namespace sonomap::harness
