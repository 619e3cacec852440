// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <string>

namespace sonomap::harness {

// "VERSION (git describe)": the provenance written into every result (summary.json, markers).
// Defined in a file generated at configure time, so a new commit recompiles only that file.
std::string code_version();

}  // namespace sonomap::harness
