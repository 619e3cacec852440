// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap render`: a scenario's simulated depth frames as a TUM RGB-D sequence.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace sonomap::harness {

// Renders `scenario` (with "key=value" overrides, e.g. frames=, seed=) into `out`, written
// whole or not at all; an earlier sequence there is replaced, anything else is an InputError.
void render_sequence(const std::filesystem::path& scenario, const std::vector<std::string>& overrides,
                     const std::filesystem::path& out, bool quiet);

}  // namespace sonomap::harness
