// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/scenario_keys.hpp"

#include <stdexcept>

namespace sonomap::harness {
namespace {

constexpr double kMaxTime = 1e6;       // s
constexpr double kMaxAngle = 3600.0;   // degrees (ten turns, for keyframes that keep turning)
constexpr double kMaxSize = 2e4;       // m: an object spans at most the 10 km world both ways
constexpr double kMaxPixels = 16384.0;
constexpr double kMaxFocal = 1e6;      // px: a 16384 px image over a 1 degree view

ScenarioKey num(std::string pattern, std::string unit, double lo, double hi, std::string doc) {
  return {std::move(pattern), false, std::move(unit), {lo, hi, false}, std::move(doc)};
}
ScenarioKey pos(std::string pattern, std::string unit, double hi, std::string doc) {
  return {std::move(pattern), false, std::move(unit), {0.0, hi, true}, std::move(doc)};
}
ScenarioKey whole(std::string pattern, double lo, double hi, std::string doc) {
  return {std::move(pattern), true, "", {lo, hi, false}, std::move(doc)};
}

// "a[3].b[0]" -> "a[].b[]".
std::string pattern_of(const std::string& key) {
  std::string out;
  for (std::size_t i = 0; i < key.size(); ++i) {
    out += key[i];
    if (key[i] == '[') {
      while (i + 1 < key.size() && key[i + 1] != ']') ++i;
    }
  }
  return out;
}

bool matches(const std::string& pattern, const std::string& key) {
  if (pattern.rfind("*.", 0) != 0) return pattern == key;
  const std::string tail = pattern.substr(1);  // ".position"
  return key == tail.substr(1) ||
         (key.size() > tail.size() && key.compare(key.size() - tail.size(), tail.size(), tail) == 0);
}

}  // namespace

const std::vector<ScenarioKey>& scenario_keys() {
  static const std::vector<ScenarioKey> keys = {
      whole("frames", 1, kMaxFrames, "number of frames (or give duration)"),
      pos("duration", "s", kMaxTime, "seconds of sensing; frames = duration x rate"),
      num("ground_z", "m", -kMaxPosition, kMaxPosition, "height of the ground plane"),
      whole("sensor.width", 1, kMaxPixels, "image width, pixels"),
      whole("sensor.height", 1, kMaxPixels, "image height, pixels"),
      num("sensor.intrinsics.fx", "px", 1.0, kMaxFocal, "focal length along x"),
      num("sensor.intrinsics.fy", "px", 1.0, kMaxFocal, "focal length along y"),
      num("sensor.intrinsics.cx", "px", 0.0, kMaxPixels, "principal point x (within the width)"),
      num("sensor.intrinsics.cy", "px", 0.0, kMaxPixels, "principal point y (within the height)"),
      num("sensor.min_range", "m", 0.0, kMaxRange, "nearest depth the camera returns"),
      pos("sensor.max_range", "m", kMaxRange, "farthest depth the camera returns"),
      pos("sensor.rate", "Hz", kMaxRate, "frames per second"),
      num("sensor.noise.dropout", "", 0.0, 1.0, "probability a valid pixel is dropped"),
      pos("sensor.noise.baseline", "m", 10.0, "stereo baseline of the Kinect model"),
      pos("sensor.noise.disparity_step", "px", 100.0, "disparity quantisation step"),
      pos("sensor.noise.edge_threshold", "m", kMaxRange, "depth jump that marks an edge"),
      pos("sensor.noise.grazing_angle", "deg", 90.0, "incidence beyond which there is no return"),
      num("localisation.translation_noise", "m", 0.0, kMaxRange, "per-frame position noise (sigma)"),
      num("localisation.yaw_noise", "deg", 0.0, 180.0, "per-frame heading noise (sigma)"),
      num("localisation.translation_drift", "m/sqrt(s)", 0.0, kMaxRange, "position random walk"),
      num("localisation.yaw_drift", "deg/sqrt(s)", 0.0, 180.0, "heading random walk"),
      num("localisation.time_offset", "s", -3600.0, 3600.0, "the pose is taken at frame time + offset"),
      pos("depth_scale", "1/m", 1e6, "camera.yaml: depth PNG units per metre"),
      num("*.time", "s", -kMaxTime, kMaxTime, "keyframe time"),
      num("*.appear", "s", -kMaxTime, kMaxTime, "time a moving object appears"),
      num("*.disappear", "s", -kMaxTime, kMaxTime, "time a moving object disappears"),
      num("*.position", "m", -kMaxPosition, kMaxPosition, "x, y, z of a pose, keyframe or mounting"),
      num("*.yaw", "deg", -kMaxAngle, kMaxAngle, "turn about z (left positive)"),
      num("*.pitch", "deg", -kMaxAngle, kMaxAngle, "turn about y (positive tilts x down)"),
      num("*.roll", "deg", -kMaxAngle, kMaxAngle, "turn about x"),
      num("*.quaternion", "", -1.0, 1.0, "unit quaternion x, y, z, w"),
      pos("*.size", "m", kMaxSize, "room, box or plane extents"),
      pos("*.radius", "m", kMaxSize / 2, "cylinder or sphere radius"),
      pos("*.height", "m", kMaxSize, "cylinder height"),
      whole("*.segments", 3, 4096, "cylinder or sphere tessellation"),
      pos("*.scale", "", 1e4, "mesh file units to metres"),
  };
  return keys;
}

const ScenarioKey& scenario_key(const std::string& key) {
  std::string pattern = pattern_of(key);
  if (pattern.size() > 2 && pattern.compare(pattern.size() - 2, 2, "[]") == 0)
    pattern.resize(pattern.size() - 2);  // a vector's component: the vector's bounds
  for (const ScenarioKey& k : scenario_keys())
    if (matches(k.pattern, pattern) || matches(k.pattern, "sensor." + pattern)) return k;
  throw std::logic_error("scenario key '" + key + "' has no declared bounds");
}

std::string scenario_keys_markdown() {
  std::string text = "| key | range | meaning |\n| --- | --- | --- |\n";
  for (const ScenarioKey& k : scenario_keys())
    text += "| `" + k.pattern + "` | " + k.range.text() + (k.unit.empty() ? "" : " " + k.unit) +
            (k.whole ? " (whole)" : "") + " | " + k.doc + " |\n";
  return text;
}

}  // namespace sonomap::harness
