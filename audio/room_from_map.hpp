// SPDX-License-Identifier: GPL-3.0-or-later
// The paper's "room from the map": when no measured BRIRs are given, the sweep is rendered in
// a shoebox room that is the bounding box of what the map holds around the listener.
#pragma once

#include "audio/brir_synth.hpp"

#include <Eigen/Core>
#include <vector>

namespace sonomap::audio {

// The bounding box of `map_points` and the listener, reaching down to the ground, grown about
// its centre to at least 2 x 2 x 2.4 m and so that the listener stands at least 0.3 m off
// every wall (the image-source model needs the head inside the room).
ShoeboxRoom room_from_map(const std::vector<Eigen::Vector3f>& map_points,
                          const Eigen::Vector3d& listener, double ground_z);

}  // namespace sonomap::audio
