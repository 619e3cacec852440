// SPDX-License-Identifier: GPL-3.0-or-later
// The scenario reader (`sonomap run SCENARIO.yaml`) on arbitrary bytes, then the simulator's
// own validation, as `run` does.
#include "fuzz_support.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/support/errors.hpp"
#include "sim/simulation.hpp"

#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = sonomap::fuzz::write_file(
      "scenario.yaml", std::string(reinterpret_cast<const char*>(data), size));
  try {
    const sonomap::sim::Scenario scenario = sonomap::harness::load_scenario(file);
    sonomap::sim::validate(scenario);
  } catch (const sonomap::harness::InputError&) {
  } catch (const std::invalid_argument&) {  // sim::validate's: `run` reports it as InputError
  }
  return 0;
}
