// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap render`: a scenario's simulated depth frames as a TUM RGB-D sequence or a ROS1 bag.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace sonomap::harness {

// Renders `scenario` (with "key=value" overrides, e.g. frames=, seed=) into `out`, written
// whole or not at all; an earlier sequence there is replaced, anything else is an InputError.
void render_sequence(const std::filesystem::path& scenario, const std::vector<std::string>& overrides,
                     const std::filesystem::path& out, bool quiet);

// Renders `scenario` into `out` as a ROS1 bag in the Cow and Lady topic layout (docs/real-data.md):
// out/data.bag, out/truth.ply (the static scene sampled with a covering radius of at most
// `truth_spacing` metres) and out/sequence.yaml, which runs the bag with that truth. Output
// rules as for render_sequence.
void render_rosbag(const std::filesystem::path& scenario, const std::vector<std::string>& overrides,
                   const std::filesystem::path& out, double truth_spacing, bool quiet);

}  // namespace sonomap::harness
