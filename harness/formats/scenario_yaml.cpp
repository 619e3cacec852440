// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/scenario_yaml.hpp"

#include "harness/formats/mesh_io.hpp"
#include "harness/formats/scenario_keys.hpp"
#include "harness/support/errors.hpp"
#include "sim/primitives.hpp"
#include "sim/trajectory.hpp"

#include <yaml-cpp/yaml.h>

#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <system_error>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

constexpr double kPi = 3.14159265358979323846;
double radians(double degrees) { return degrees * kPi / 180.0; }

// "a.b" is a prefix of "a.b", "a.b.c" and "a.b[2]", not of "a.bc".
bool key_within(const std::string& outer, const std::string& key) {
  if (key.compare(0, outer.size(), outer) != 0) return false;
  return key.size() == outer.size() || key[outer.size()] == '.' || key[outer.size()] == '[';
}

std::string item_key(const std::string& key, std::size_t index) {
  return key + "[" + std::to_string(index) + "]";
}

std::string child_key(const std::string& key, const std::string& name) {
  return key.empty() ? name : key + "." + name;
}

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  return "a map";
}

struct Override {
  std::string key;   // normalised: sequence items as [i]
  std::string text;  // as the user wrote it
};

// Turns a problem at a node into an InputError naming the file, line and key, or the override
// the value came from.
class Context {
 public:
  Context(std::string file, fs::path dir) : file_(std::move(file)), dir_(std::move(dir)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& key,
                         const std::string& what) const {
    const bool from_file = node.IsDefined() && !node.Mark().is_null();
    for (auto it = overrides_.rbegin(); it != overrides_.rend(); ++it) {
      // The value came from the override, or the key itself was created by it.
      if (key_within(it->key, key) || (!from_file && key_within(key, it->key)))
        throw InputError(file_, 0, key, what + " (set by --set '" + it->text + "')");
    }
    throw InputError(file_, from_file ? node.Mark().line + 1 : 0, key, what);
  }

  const std::string& file() const { return file_; }
  const fs::path& dir() const { return dir_; }
  void add_override(Override o) { overrides_.push_back(std::move(o)); }

  // Runs `read`; the InputError it throws is kept (the first kMaxErrors of them) and reading
  // goes on, so that one run reports every problem of the file. False if `read` failed.
  template <typename Read>
  bool attempt(Read read) const {
    try {
      read();
      return true;
    } catch (const InputError& e) {
      if (errors_.size() < kMaxErrors) errors_.emplace_back(e.what());
      else ++errors_left_off_;
      return false;
    }
  }
  // Throws all kept errors as one InputError (one line each), if there are any.
  void throw_errors() const {
    if (errors_.empty()) return;
    if (errors_.size() == 1) throw InputError(errors_[0]);
    std::string text = std::to_string(errors_.size() + errors_left_off_) + " problems in " + file_ + ":";
    for (const std::string& e : errors_) text += "\n  " + e;
    if (errors_left_off_ > 0) text += "\n  (" + std::to_string(errors_left_off_) + " more not shown)";
    throw InputError(text);
  }

 private:
  static constexpr std::size_t kMaxErrors = 20;
  std::string file_;
  fs::path dir_;
  std::vector<Override> overrides_;
  mutable std::vector<std::string> errors_;
  mutable std::size_t errors_left_off_ = 0;
};

// --- scalars and vectors -------------------------------------------------------------------

double to_number(const Context& ctx, const YAML::Node& node, const std::string& key) {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value))
    ctx.fail(node, key, "expected a number, got " + describe(node));
  if (!std::isfinite(value)) ctx.fail(node, key, "expected a finite number, got " + describe(node));
  const ScenarioKey& declared = scenario_key(key);
  if (!declared.range.contains(value))
    ctx.fail(node, key, describe(node) + " is out of range: expected " + declared.range.text() +
                            (declared.unit.empty() ? "" : " " + declared.unit));
  return value;
}

long long to_integer(const Context& ctx, const YAML::Node& node, const std::string& key) {
  long long value = 0;
  if (!node.IsScalar() || !YAML::convert<long long>::decode(node, value))
    ctx.fail(node, key, "expected a whole number, got " + describe(node));
  const Range& range = scenario_key(key).range;
  if (!range.contains(static_cast<double>(value)))
    ctx.fail(node, key, describe(node) + " is out of range: expected a whole number in " + range.text());
  return value;
}

bool to_flag(const Context& ctx, const YAML::Node& node, const std::string& key) {
  bool value = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value))
    ctx.fail(node, key, "expected true or false, got " + describe(node));
  return value;
}

std::string to_text(const Context& ctx, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar() || node.Scalar().empty())
    ctx.fail(node, key, "expected a non-empty text, got " + describe(node));
  return node.Scalar();
}

Eigen::VectorXd to_vector(const Context& ctx, const YAML::Node& node, const std::string& key,
                          std::size_t n) {
  if (!node.IsSequence() || node.size() != n)
    ctx.fail(node, key,
             "expected a list of " + std::to_string(n) + " numbers, got " + describe(node) +
                 (node.IsSequence() ? " of " + std::to_string(node.size()) : std::string()));
  Eigen::VectorXd v(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i)
    v[static_cast<Eigen::Index>(i)] = to_number(ctx, node[i], item_key(key, i));
  return v;
}

// --- maps ----------------------------------------------------------------------------------

// A YAML map read with a fixed set of allowed keys: unknown or repeated keys are errors,
// so a typo never falls back to a default.
class MapReader {
 public:
  MapReader(const Context& ctx, const YAML::Node& node, std::string key,
            const std::vector<std::string>& allowed)
      : ctx_(ctx), node_(node), key_(std::move(key)) {
    if (!node_.IsMap()) ctx_.fail(node_, key_, "expected a map (key: value), got " + describe(node_));
    std::set<std::string> seen;
    for (const auto& entry : node_) {
      if (!entry.first.IsScalar())
        ctx_.fail(entry.first, key_, "map keys must be plain names");
      const std::string name = entry.first.Scalar();
      bool known = false;
      std::string list;
      for (const std::string& a : allowed) {
        known = known || name == a;
        list += (list.empty() ? "" : ", ") + a;
      }
      ctx_.attempt([&] {
        if (!known) ctx_.fail(entry.first, sub(name), "unknown key (allowed here: " + list + ")");
        if (!seen.insert(name).second) ctx_.fail(entry.first, sub(name), "key given twice");
      });
    }
  }

  std::string sub(const std::string& name) const { return child_key(key_, name); }
  const YAML::Node& node() const { return node_; }
  const std::string& key() const { return key_; }
  const Context& ctx() const { return ctx_; }

  bool has(const std::string& name) const { return static_cast<bool>(node_[name]); }

  YAML::Node required(const std::string& name) const {
    YAML::Node n = node_[name];
    if (!n) ctx_.fail(node_, sub(name), "missing required key");
    return n;
  }

  // Optional values: a bad one is kept as an error (Context::attempt) and the fallback used,
  // so the reader goes on and finds the file's other problems.
  double number(const std::string& name, double fallback) const {
    return value(name, fallback, [&] { return to_number(ctx_, node_[name], sub(name)); });
  }
  double number(const std::string& name) const {
    return to_number(ctx_, required(name), sub(name));
  }
  // A number that must also satisfy `ok`; `rule` says what is expected.
  template <typename Ok>
  double checked(const std::string& name, double fallback, Ok ok, const char* rule) const {
    const double v = number(name, fallback);
    if (has(name) && !ok(v)) ctx_.attempt([&] { ctx_.fail(node_[name], sub(name), std::string(rule)); });
    return ok(v) ? v : fallback;
  }
  int integer(const std::string& name, int fallback) const {
    return static_cast<int>(value(name, static_cast<long long>(fallback),
                                  [&] { return to_integer(ctx_, node_[name], sub(name)); }));
  }
  bool flag(const std::string& name, bool fallback) const {
    return value(name, fallback, [&] { return to_flag(ctx_, node_[name], sub(name)); });
  }
  std::string text(const std::string& name, const std::string& fallback) const {
    return value(name, fallback, [&] { return to_text(ctx_, node_[name], sub(name)); });
  }
  Eigen::Vector3d vector3(const std::string& name, const Eigen::Vector3d& fallback) const {
    return value(name, fallback,
                 [&] { return Eigen::Vector3d(to_vector(ctx_, node_[name], sub(name), 3)); });
  }
  [[noreturn]] void fail(const std::string& name, const std::string& what) const {
    ctx_.fail(has(name) ? node_[name] : node_, sub(name), what);
  }

 private:
  template <typename T, typename Read>
  T value(const std::string& name, T fallback, Read read) const {
    T v = fallback;
    if (has(name)) ctx_.attempt([&] { v = read(); });
    return v;
  }

  const Context& ctx_;
  YAML::Node node_;
  std::string key_;
};

YAML::Node require_sequence(const Context& ctx, const YAML::Node& node, const std::string& key) {
  if (!node.IsSequence()) ctx.fail(node, key, "expected a list, got " + describe(node));
  return node;
}

// --- poses and trajectories ----------------------------------------------------------------

// yaw/pitch/roll in degrees, or a unit quaternion [x, y, z, w] (TUM order) for exact poses.
Eigen::Quaterniond read_orientation(const MapReader& map) {
  if (!map.has("quaternion"))
    return quaternion_from_ypr_degrees(map.number("yaw", 0.0), map.number("pitch", 0.0),
                                       map.number("roll", 0.0));
  for (const char* angle : {"yaw", "pitch", "roll"})
    if (map.has(angle))
      map.fail(angle, "give the orientation either as yaw/pitch/roll or as a quaternion, not both");
  const Eigen::VectorXd q = to_vector(map.ctx(), map.node()["quaternion"], map.sub("quaternion"), 4);
  if (std::abs(q.norm() - 1.0) > 1e-3)
    map.fail("quaternion", "expected a unit quaternion [x, y, z, w], its norm is " +
                               std::to_string(q.norm()));
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
}

Eigen::Isometry3d read_pose(const Context& ctx, const YAML::Node& node, const std::string& key) {
  const MapReader map(ctx, node, key, {"position", "yaw", "pitch", "roll", "quaternion"});
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = read_orientation(map).toRotationMatrix();
  pose.translation() = map.vector3("position", Eigen::Vector3d::Zero());
  return pose;
}

sim::Interpolation read_interpolation(const MapReader& map) {
  const std::string name = to_text(map.ctx(), map.required("interpolation"), map.sub("interpolation"));
  if (name == "linear_slerp") return sim::Interpolation::LinearSlerp;
  map.fail("interpolation", "unknown interpolation '" + name + "' (known: linear_slerp)");
}

// The listener's head: yaw/pitch keyframes, relative to the body (default) or to the world.
sim::HeadSpec read_head(const Context& ctx, const YAML::Node& node) {
  const MapReader map(ctx, node, "head", {"relative_to", "keyframes"});
  sim::HeadSpec head;
  const std::string frame = map.text("relative_to", "body");
  if (frame != "body" && frame != "world")
    map.fail("relative_to", "expected body or world, got '" + frame + "'");
  head.absolute = frame == "world";
  const YAML::Node frames = require_sequence(ctx, map.required("keyframes"), "head.keyframes");
  if (frames.size() == 0) ctx.fail(frames, "head.keyframes", "the head has no keyframes");
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::string k = item_key("head.keyframes", i);
    ctx.attempt([&] {
      const MapReader kf(ctx, frames[i], k, {"time", "yaw", "pitch"});
      const sim::HeadKeyframe keyframe{kf.number("time"), kf.number("yaw", 0.0), kf.number("pitch", 0.0)};
      if (std::abs(keyframe.pitch_deg) > 90.0) kf.fail("pitch", "head pitch must be in [-90, 90] degrees");
      if (!head.keyframes.empty() && !(keyframe.time > head.keyframes.back().time))
        kf.fail("time", "keyframe times must increase: " + std::to_string(keyframe.time) +
                            " s is not after " + std::to_string(head.keyframes.back().time) + " s");
      head.keyframes.push_back(keyframe);
    });
  }
  return head;
}

sim::TrajectorySpec read_trajectory(const Context& ctx, const YAML::Node& node,
                                    const std::string& key) {
  const MapReader map(ctx, node, key, {"interpolation", "keyframes"});
  sim::TrajectorySpec trajectory;
  trajectory.interpolation = read_interpolation(map);
  const std::string frames_key = map.sub("keyframes");
  const YAML::Node frames = require_sequence(ctx, map.required("keyframes"), frames_key);
  if (frames.size() == 0) ctx.fail(frames, frames_key, "the trajectory has no keyframes");
  bool all_read = true;  // otherwise the keyframe's own error says it all
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::string k = item_key(frames_key, i);
    all_read &= ctx.attempt([&] {
      const MapReader kf(ctx, frames[i], k, {"time", "position", "yaw", "pitch", "roll", "quaternion"});
      sim::Keyframe keyframe;
      keyframe.time = kf.number("time");
      keyframe.position = to_vector(ctx, kf.required("position"), kf.sub("position"), 3);
      keyframe.orientation = read_orientation(kf);
      if (!trajectory.keyframes.empty()) {
        const sim::Keyframe& previous = trajectory.keyframes.back();
        if (!(keyframe.time > previous.time))
          kf.fail("time", "keyframe times must increase: " + std::to_string(keyframe.time) +
                              " s is not after " + std::to_string(previous.time) + " s");
        // Slerp takes the shorter way round: a half turn or more between two keyframes would
        // not turn the way the file seems to say.
        const double turn = previous.orientation.angularDistance(keyframe.orientation);
        if (turn >= radians(179.0))
          kf.fail(kf.has("yaw") ? "yaw" : kf.has("quaternion") ? "quaternion" : "time",
                  "turns " + std::to_string(turn * 180.0 / kPi) +
                      " degrees since the previous keyframe; interpolation takes the shorter way, "
                      "so keep each turn under 179 degrees (add keyframes)");
      }
      trajectory.keyframes.push_back(keyframe);
    });
  }
  try {
    if (all_read) sim::validate(trajectory);
  } catch (const std::invalid_argument& e) {
    ctx.fail(node, key, e.what());
  }
  return trajectory;
}

// --- shapes --------------------------------------------------------------------------------

constexpr const char* kShapeKeys[] = {"room", "box", "cylinder", "sphere", "plane", "mesh"};

// The one shape key of an object ("box: {size: [...]}") as a primitive with its mesh.
void read_shape(const MapReader& object, sim::PrimitiveSpec& shape, sim::TriangleMesh& mesh) {
  const Context& ctx = object.ctx();
  std::string found;
  for (const char* name : kShapeKeys) {
    if (!object.has(name)) continue;
    if (!found.empty())
      object.fail(name, "an object has one shape, but this one has both '" + found + "' and '" +
                            name + "'");
    found = name;
  }
  if (found.empty())
    ctx.fail(object.node(), object.key(),
             "missing the shape: one of room, box, cylinder, sphere, plane, mesh");
  const std::string key = object.sub(found);
  const YAML::Node node = object.node()[found];
  using Kind = sim::PrimitiveSpec::Kind;
  if (found == "room" || found == "box") {
    const MapReader m(ctx, node, key, {"size"});
    shape.kind = found == "room" ? Kind::Room : Kind::Box;
    shape.size = to_vector(ctx, m.required("size"), m.sub("size"), 3);
    if ((shape.size.array() <= 0.0).any()) m.fail("size", "every size must be > 0");
  } else if (found == "plane") {
    const MapReader m(ctx, node, key, {"size"});
    shape.kind = Kind::Plane;
    const Eigen::VectorXd xy = to_vector(ctx, m.required("size"), m.sub("size"), 2);
    if ((xy.array() <= 0.0).any()) m.fail("size", "every size must be > 0");
    shape.size = Eigen::Vector3d(xy[0], xy[1], 0.0);
  } else if (found == "cylinder" || found == "sphere") {
    const bool cylinder = found == "cylinder";
    const MapReader m = cylinder ? MapReader(ctx, node, key, {"radius", "height", "segments"})
                                 : MapReader(ctx, node, key, {"radius", "segments"});
    shape.kind = cylinder ? Kind::Cylinder : Kind::Sphere;
    m.required("radius");
    shape.radius = m.number("radius", 0.0);
    if (cylinder) {
      m.required("height");
      shape.height = m.number("height", 0.0);
    }
    shape.segments = m.integer("segments", shape.segments);
  } else {
    const MapReader m(ctx, node, key, {"file", "scale"});
    shape.kind = Kind::Mesh;
    fs::path file = to_text(ctx, m.required("file"), m.sub("file"));
    if (file.is_relative()) file = ctx.dir() / file;
    const double scale = m.number("scale", 1.0);
    shape.mesh_path = file.lexically_normal().string();
    try {
      mesh = load_mesh(file);
    } catch (const InputError& e) {
      m.fail("file", e.what());
    }
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      Eigen::Vector3f& v = mesh.vertices[i];
      v *= static_cast<float>(scale);
      if (!v.allFinite() || v.cwiseAbs().maxCoeff() > kMaxPosition)
        m.fail("file", "vertex " + std::to_string(i) + " lies beyond " + number_text(kMaxPosition) +
                           " m of the object's origin (or is not finite) at scale " + number_text(scale));
    }
    return;
  }
  try {
    mesh = sim::triangulate(shape);
  } catch (const std::invalid_argument& e) {
    ctx.fail(node, key, e.what());
  }
}

std::vector<sim::StaticObject> read_statics(const Context& ctx, const YAML::Node& node) {
  std::vector<sim::StaticObject> statics;
  require_sequence(ctx, node, "static");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string key = item_key("static", i);
    ctx.attempt([&] {
      const MapReader map(ctx, node[i], key,
                          {"name", "pose", "room", "box", "cylinder", "sphere", "plane", "mesh"});
      sim::StaticObject object;
      object.name = map.text("name", key);
      ctx.attempt([&] { read_shape(map, object.shape, object.mesh); });
      if (map.has("pose")) object.pose = read_pose(ctx, map.node()["pose"], map.sub("pose"));
      statics.push_back(std::move(object));
    });
  }
  return statics;
}

std::vector<sim::MovingObject> read_movers(const Context& ctx, const YAML::Node& node) {
  std::vector<sim::MovingObject> movers;
  require_sequence(ctx, node, "moving");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string key = item_key("moving", i);
    ctx.attempt([&] {
      const MapReader map(ctx, node[i], key,
                          {"name", "trajectory", "appear", "disappear", "room", "box", "cylinder",
                           "sphere", "plane", "mesh"});
      sim::MovingObject object;
      object.name = map.text("name", key);
      ctx.attempt([&] { read_shape(map, object.shape, object.mesh); });
      object.trajectory = read_trajectory(ctx, map.required("trajectory"), map.sub("trajectory"));
      object.appear_time = map.number("appear", object.appear_time);
      object.disappear_time = map.number("disappear", object.disappear_time);
      if (!(object.appear_time < object.disappear_time))
        map.fail("disappear", "must be later than appear");
      movers.push_back(std::move(object));
    });
  }
  return movers;
}

// Names address objects in overrides and results, so each names one object.
void check_unique_names(const Context& ctx, const YAML::Node& root, const sim::Scenario& scenario) {
  std::set<std::string> names;
  for (std::size_t i = 0; i < scenario.statics.size(); ++i)
    if (!names.insert(scenario.statics[i].name).second)
      ctx.fail(root["static"][i], item_key("static", i) + ".name",
               "the name '" + scenario.statics[i].name + "' is used by another object");
  for (std::size_t i = 0; i < scenario.movers.size(); ++i)
    if (!names.insert(scenario.movers[i].name).second)
      ctx.fail(root["moving"][i], item_key("moving", i) + ".name",
               "the name '" + scenario.movers[i].name + "' is used by another object");
}

// --- sensor, noise, localisation -----------------------------------------------------------

void read_noise(const Context& ctx, const YAML::Node& node, sim::NoiseSpec& noise) {
  const MapReader m(ctx, node, "sensor.noise",
                    {"model", "lateral", "axial", "quantisation", "grazing_invalidation",
                     "edge_invalidation", "dropout", "baseline", "disparity_step",
                     "edge_threshold", "grazing_angle"});
  const std::string model = m.text("model", "none");
  if (model == "none")
    noise.model = sim::NoiseSpec::Model::None;
  else if (model == "kinect")
    noise.model = sim::NoiseSpec::Model::Kinect;
  else
    m.fail("model", "unknown noise model '" + model + "' (known: none, kinect)");
  noise.lateral = m.flag("lateral", noise.lateral);
  noise.axial = m.flag("axial", noise.axial);
  noise.quantisation = m.flag("quantisation", noise.quantisation);
  noise.grazing_invalidation = m.flag("grazing_invalidation", noise.grazing_invalidation);
  noise.edge_invalidation = m.flag("edge_invalidation", noise.edge_invalidation);
  noise.dropout = m.number("dropout", noise.dropout);
  noise.baseline = m.number("baseline", noise.baseline);
  noise.disparity_step = m.number("disparity_step", noise.disparity_step);
  noise.edge_threshold = m.number("edge_threshold", noise.edge_threshold);
  noise.grazing_angle = radians(m.number("grazing_angle", noise.grazing_angle * 180.0 / kPi));
}

// The camera keys shared by a scenario's `sensor` section and a sequence's camera.yaml.
std::vector<std::string> camera_keys_and(std::vector<std::string> more) {
  for (const char* key : {"width", "height", "intrinsics", "min_range", "max_range", "rate", "mounting"})
    more.emplace_back(key);
  return more;
}

void read_camera(const MapReader& m, sim::CameraSpec& camera) {
  const Context& ctx = m.ctx();
  camera.width = m.integer("width", camera.width);
  camera.height = m.integer("height", camera.height);
  if (m.has("intrinsics")) {
    const MapReader in(ctx, m.node()["intrinsics"], m.sub("intrinsics"), {"fx", "fy", "cx", "cy"});
    camera.fx = in.number("fx", camera.fx);
    camera.fy = in.number("fy", camera.fy);
    camera.cx = in.checked("cx", camera.cx, [&](double c) { return c >= 0.0 && c <= camera.width; },
                           "the principal point must lie in the image: 0 <= cx <= width");
    camera.cy = in.checked("cy", camera.cy, [&](double c) { return c >= 0.0 && c <= camera.height; },
                           "the principal point must lie in the image: 0 <= cy <= height");
  }
  ctx.attempt([&] {
    if (camera.cx > camera.width || camera.cy > camera.height)
      m.fail("intrinsics", "the principal point (cx, cy) lies outside the image; give intrinsics "
                           "that match width and height");
  });
  camera.min_range = m.number("min_range", camera.min_range);
  camera.max_range = m.number("max_range", camera.max_range);
  ctx.attempt([&] {
    if (!(camera.max_range > camera.min_range))
      m.fail(m.has("max_range") ? "max_range" : "min_range",
             "max_range (" + std::to_string(camera.max_range) + ") must be greater than min_range (" +
                 std::to_string(camera.min_range) + ")");
  });
  camera.rate_hz = m.number("rate", camera.rate_hz);
  if (m.has("mounting")) {
    // The mounting turns the camera's viewing direction relative to body forward; the optical
    // axes (z forward, x right, y down) follow from the default head mount.
    const Eigen::Isometry3d mount = read_pose(ctx, m.node()["mounting"], m.sub("mounting"));
    camera.body_T_camera = mount * sim::CameraSpec::default_body_T_camera();
  }
}

void read_sensor(const Context& ctx, const YAML::Node& node, sim::Scenario& scenario) {
  const MapReader m(ctx, node, "sensor", camera_keys_and({"noise"}));
  read_camera(m, scenario.camera);
  if (m.has("noise")) read_noise(ctx, m.node()["noise"], scenario.noise);
}

void read_localisation(const Context& ctx, const YAML::Node& node, sim::LocalisationSpec& loc) {
  const MapReader m(ctx, node, "localisation",
                    {"translation_noise", "yaw_noise", "translation_drift", "yaw_drift",
                     "time_offset"});
  loc.translation_noise = m.number("translation_noise", loc.translation_noise);
  loc.yaw_noise = radians(m.number("yaw_noise", loc.yaw_noise));
  loc.translation_drift = m.number("translation_drift", loc.translation_drift);
  loc.yaw_drift = radians(m.number("yaw_drift", loc.yaw_drift));
  loc.time_offset = m.number("time_offset", loc.time_offset);
}

// --- overrides -----------------------------------------------------------------------------

bool parse_index(const std::string& s, std::size_t& index) {
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos)
    return false;
  index = static_cast<std::size_t>(std::stoul(s));
  return true;
}

// Applies "a.b.c=value" to the document; returns the key in the form errors use.
std::string apply_override(const Context& ctx, YAML::Node& root, const std::string& text) {
  const auto bad = [&](const std::string& what) -> InputError {
    return InputError(ctx.file(), 0, "", "--set '" + text + "': " + what);
  };
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw bad("expected key=value");
  const std::string path = text.substr(0, eq);
  const std::string value_text = text.substr(eq + 1);
  if (value_text.empty()) throw bad("the value is empty");
  YAML::Node value;
  try {
    value = YAML::Load(value_text);
  } catch (const YAML::Exception& e) {
    throw bad("the value is not valid YAML: " + e.msg);
  }

  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = path.find('.', start);
    parts.push_back(path.substr(start, dot - start));
    if (parts.back().empty()) throw bad("empty part in the key '" + path + "'");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }

  if (!root.IsDefined() || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  YAML::Node node = root;
  std::string key;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (node.IsSequence()) {
      // A list item by index, or by its `name`.
      std::size_t index = node.size();
      if (!parse_index(part, index)) {
        for (std::size_t j = 0; j < node.size(); ++j)
          if (node[j].IsMap() && node[j]["name"] && node[j]["name"].IsScalar() &&
              node[j]["name"].Scalar() == part)
            index = j;
      }
      if (index >= node.size())
        throw bad("'" + child_key(key, part) + "': no such item in the list '" + key + "'");
      key = item_key(key, index);
      if (last) {
        node[index] = value;
      } else {
        YAML::Node next = node[index];
        node.reset(next);
      }
    } else if (node.IsMap()) {
      key = child_key(key, part);
      const YAML::Node& as_const = node;
      if (last) {
        node[part] = value;
      } else {
        if (!as_const[part] || as_const[part].IsNull())
          node[part] = YAML::Node(YAML::NodeType::Map);
        YAML::Node next = node[part];
        node.reset(next);
      }
    } else {
      throw bad("'" + key + "' is a single value, not a map or list, so it has no '" + part + "'");
    }
  }
  // frames and duration say the same thing: the newest one wins.
  const YAML::Node& top = root;
  if (key == "frames" && top["duration"]) root.remove("duration");
  if (key == "duration" && top["frames"]) root.remove("frames");
  return key;
}

// `frames`, or `duration` in seconds at `rate_hz`.
int read_frame_count(const MapReader& top, double rate_hz) {
  if (top.has("frames") && top.has("duration"))
    top.fail("duration", "give either frames or duration, not both");
  if (top.has("frames")) return top.integer("frames", 1);
  if (!top.has("duration")) top.fail("frames", "missing required key (give frames or duration)");
  const double frames = std::round(top.number("duration", 1.0 / rate_hz) * rate_hz);
  if (frames < 1.0 || frames > kMaxFrames)
    top.fail("duration", "gives " + number_text(frames) + " frames at " + number_text(rate_hz) +
                             " Hz; need 1 to " + std::to_string(kMaxFrames));
  return static_cast<int>(frames);
}

YAML::Node load_yaml(const fs::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(name, 0, "", "file does not exist");
  if (!fs::is_regular_file(file, ec)) throw InputError(name, 0, "", "not a regular file");
  try {
    return YAML::LoadFile(name);
  } catch (const YAML::ParserException& e) {
    throw InputError(name, e.mark.is_null() ? 0 : e.mark.line + 1, "", "malformed YAML: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw InputError(name, 0, "", "cannot read the file: " + e.msg);
  }
}

}  // namespace

Eigen::Quaterniond quaternion_from_ypr_degrees(double yaw, double pitch, double roll) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(radians(yaw), Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(radians(pitch), Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(radians(roll), Eigen::Vector3d::UnitX()))
      .normalized();
}

sim::Scenario load_scenario(const fs::path& file, const std::vector<std::string>& overrides) {
  const std::string name = file.string();
  Context ctx(name, file.parent_path());
  YAML::Node root = load_yaml(file);
  for (const std::string& text : overrides) ctx.add_override({apply_override(ctx, root, text), text});
  if (!root.IsDefined() || root.IsNull())
    throw InputError(name, 0, "", "the file is empty; expected a scenario (see scenes/README.md)");

  const MapReader top(ctx, root, "",
                      {"name", "seed", "frames", "duration", "ground_z", "sensor", "localisation",
                       "body", "head", "static", "moving"});
  sim::Scenario scenario;
  scenario.source_path = name;
  scenario.name = top.text("name", file.stem().string());
  if (top.has("seed"))
    ctx.attempt([&] {
      if (!root["seed"].IsScalar() || !parse_seed(root["seed"].Scalar(), scenario.seed))
        top.fail("seed", "expected a whole number in [0, 2^63-1], got " + describe(root["seed"]));
    });
  scenario.ground_z = top.number("ground_z", scenario.ground_z);
  if (top.has("sensor")) ctx.attempt([&] { read_sensor(ctx, root["sensor"], scenario); });
  if (top.has("localisation"))
    ctx.attempt([&] { read_localisation(ctx, root["localisation"], scenario.localisation); });
  ctx.attempt([&] { scenario.frames = read_frame_count(top, scenario.camera.rate_hz); });
  ctx.attempt([&] { scenario.body = read_trajectory(ctx, top.required("body"), "body"); });
  if (top.has("head")) ctx.attempt([&] { scenario.head = read_head(ctx, root["head"]); });
  if (top.has("static")) ctx.attempt([&] { scenario.statics = read_statics(ctx, root["static"]); });
  if (top.has("moving")) ctx.attempt([&] { scenario.movers = read_movers(ctx, root["moving"]); });
  ctx.attempt([&] { check_unique_names(ctx, root, scenario); });
  ctx.throw_errors();
  return scenario;
}

CameraFile load_camera_file(const fs::path& file) {
  const std::string name = file.string();
  const Context ctx(name, file.parent_path());
  const YAML::Node root = load_yaml(file);
  if (!root.IsDefined() || root.IsNull()) throw InputError(name, 0, "", "the file is empty");
  const MapReader m(ctx, root, "", camera_keys_and({"name", "depth_scale"}));
  CameraFile result;
  result.name = m.text("name", "");
  read_camera(m, result.camera);
  result.depth_scale = m.number("depth_scale", result.depth_scale);
  ctx.throw_errors();
  return result;
}

std::string camera_file_text(const CameraFile& file) {
  const sim::CameraSpec& c = file.camera;
  const Eigen::Isometry3d mount =
      c.body_T_camera * sim::CameraSpec::default_body_T_camera().inverse();
  const Eigen::Quaterniond q(mount.linear());
  const Eigen::Vector3d p = mount.translation();
  std::string out;
  const auto line = [&](const std::string& text) { out += text + "\n"; };
  const auto num = number_text;  // reads back exactly
  line("# Camera of this sequence (sonomap camera file; format: scenes/README.md).");
  line("# Depth PNG value / depth_scale = z-depth in metres; 0 = no return.");
  if (!file.name.empty()) line("name: " + file.name);
  line("width: " + std::to_string(c.width));
  line("height: " + std::to_string(c.height));
  line("intrinsics: {fx: " + num(c.fx) + ", fy: " + num(c.fy) + ", cx: " + num(c.cx) +
       ", cy: " + num(c.cy) + "}");
  line("min_range: " + num(c.min_range));
  line("max_range: " + num(c.max_range));
  line("rate: " + num(c.rate_hz));
  line("depth_scale: " + num(file.depth_scale));
  line("# Camera on the body (x forward, y left, z up), relative to the default head mount.");
  line("mounting: {position: [" + num(p.x()) + ", " + num(p.y()) + ", " + num(p.z()) +
       "], quaternion: [" + num(q.x()) + ", " + num(q.y()) + ", " + num(q.z()) + ", " +
       num(q.w()) + "]}");
  return out;
}

}  // namespace sonomap::harness
