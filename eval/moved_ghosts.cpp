// SPDX-License-Identifier: GPL-3.0-or-later
#include "eval/moved_ghosts.hpp"

#include "core/pixel.hpp"
#include "eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sonomap::eval {
namespace {

constexpr double kMinCell = 0.02;  // m: a tolerance of 0 still gets a grid of finite size
constexpr std::int64_t kKeyOffset = std::int64_t{1} << 20;  // 2^21 cells per axis, centred

}  // namespace

double MovedGhostsConfig::cell_size() const { return std::max(0.5 * tolerance, kMinCell); }

void MovedGhostsConfig::validate() const {
  if (!std::isfinite(tolerance) || tolerance < 0.0)
    throw std::invalid_argument("moved ghosts: tolerance must be finite and >= 0");
  if (!std::isfinite(ground_z)) throw std::invalid_argument("moved ghosts: ground_z must be finite");
  raster.validate();
}

MovedGhosts::MovedGhosts(std::vector<MovingObjectShape> objects, const MovedGhostsConfig& config)
    : config_(config) {
  config_.validate();
  cell_ = config_.cell_size();
  for (auto& shape : objects) {
    if (shape.box.isEmpty() || !shape.box.min().allFinite() || !shape.box.max().allFinite())
      throw std::invalid_argument("moved ghosts: object '" + shape.name + "' has an empty box");
    Tracked t;
    t.result.name = shape.name;
    t.shape = std::move(shape);
    objects_.push_back(std::move(t));
  }
}

// The grid key of cell (x, y, z): 21 bits per axis (positions within 10 km fit at 2 cm).
static std::uint64_t key_of_cell(std::int64_t x, std::int64_t y, std::int64_t z) {
  std::uint64_t key = 0;
  for (const std::int64_t i : {x, y, z})
    key = (key << 21) | static_cast<std::uint64_t>(std::clamp<std::int64_t>(i + kKeyOffset, 0, 2 * kKeyOffset - 1));
  return key;
}

std::uint64_t MovedGhosts::key_of(const Eigen::Vector3d& p) const {
  const auto cell = [&](double v) { return static_cast<std::int64_t>(std::floor(v / cell_)); };
  return key_of_cell(cell(p.x()), cell(p.y()), cell(p.z()));
}

// Marks the cells whose centres lie in the object's box at `pose` grown by the tolerance (and
// at the circle's heights, to half a cell) as held now; a held cell forgets having been seen
// empty, so a place the object comes back to starts afresh when it leaves again.
void MovedGhosts::occupy(Tracked& object, const Eigen::Isometry3d& pose, int frame) {
  if (!object.held_pose || object.held_pose->matrix() != pose.matrix()) place(object, pose);  // moved
  for (int i : object.held) {
    object.cells[i].occupied_at = frame;
    object.cells[i].seen_empty_at = -1;
  }
}

// The cells of the object's place at `pose` (added to its cells when new) as object.held.
void MovedGhosts::place(Tracked& object, const Eigen::Isometry3d& pose) {
  object.held.clear();
  object.held_pose = pose;
  const Eigen::Vector3d grow = Eigen::Vector3d::Constant(config_.tolerance);
  const Eigen::AlignedBox3d local(object.shape.box.min() - grow, object.shape.box.max() + grow);
  Eigen::AlignedBox3d world;
  for (int c = 0; c < 8; ++c) world.extend(pose * local.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)));
  const double z_lo = config_.ground_z + config_.raster.band_min - 0.5 * cell_;
  const double z_hi = config_.ground_z + config_.raster.band_max + 0.5 * cell_;
  world = world.intersection(Eigen::AlignedBox3d(Eigen::Vector3d(world.min().x(), world.min().y(), z_lo),
                                                 Eigen::Vector3d(world.max().x(), world.max().y(), z_hi)));
  if (world.isEmpty()) return;
  const Eigen::Isometry3d object_T_world = pose.inverse();
  const Eigen::Array3i lo = (world.min().array() / cell_).floor().cast<int>();
  const Eigen::Array3i hi = (world.max().array() / cell_).floor().cast<int>();
  for (int x = lo.x(); x <= hi.x(); ++x)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int z = lo.z(); z <= hi.z(); ++z) {
        const Eigen::Vector3d centre = (Eigen::Vector3d(x, y, z).array() + 0.5) * cell_;
        if (centre.z() < z_lo || centre.z() > z_hi || !local.contains(object_T_world * centre)) continue;
        const auto [it, added] = object.index.try_emplace(key_of_cell(x, y, z), static_cast<int>(object.cells.size()));
        if (added) object.cells.push_back({centre});
        object.held.push_back(it->second);
      }
}

// The camera looks through world point p when p projects into the depth image and the reading
// at that pixel lies beyond p (z-depth) by more than the tolerance. A pixel without a return
// does not count.
bool MovedGhosts::seen_through(const Eigen::Vector3d& world_point, const Frame& depth,
                               const Eigen::Isometry3d& camera_T_world) const {
  if (!depth.intrinsics.valid()) return false;
  const Eigen::Vector3d p = camera_T_world * world_point;
  const std::optional<Pixel> px = pixel_of(depth.intrinsics, depth.width, depth.height, p);
  if (!px) return false;
  const double reading = depth.depth[static_cast<std::size_t>(px->v) * depth.width + px->u];
  return reading > 0.0 && reading > p.z() + config_.tolerance;
}

void MovedGhosts::mark_seen(Tracked& object, Cell& cell, int frame) {
  cell.seen_empty_at = frame;
  if (!object.result.seen_empty_frame) object.result.seen_empty_frame = frame;
}

// Vacated cells whose centres the camera looks through are seen empty from this frame.
void MovedGhosts::look_through(Tracked& object, const Frame& depth, const Eigen::Isometry3d& camera_T_world,
                               int frame) {
  for (Cell& cell : object.cells)
    if (cell.occupied_at != frame && cell.seen_empty_at < 0 && seen_through(cell.centre, depth, camera_T_world))
      mark_seen(object, cell, frame);
}

void MovedGhosts::check_input(int frame, std::size_t poses, const Circle& estimate, const Circle& truth,
                              const Frame& depth) const {
  if (poses != objects_.size())
    throw std::invalid_argument("moved ghosts: " + std::to_string(poses) + " poses for " +
                                std::to_string(objects_.size()) + " objects");
  if (estimate.size() != truth.size())
    throw std::invalid_argument("moved ghosts: estimate and truth circles differ in size");
  if (depth.depth.size() != static_cast<std::size_t>(depth.width) * static_cast<std::size_t>(std::max(depth.height, 0)))
    throw std::invalid_argument("moved ghosts: depth image is not width x height");
  if (frame <= last_frame_)
    throw std::invalid_argument("moved ghosts: frame " + std::to_string(frame) + " after frame " +
                                std::to_string(last_frame_));
}

// Which objects' vacated cells the ghost bin's estimate point q lies in; notes the seen ones'
// ages (frames since seen empty) for the clearing figure.
void MovedGhosts::read_bin(const Eigen::Vector3d& q, int frame, const Frame& depth,
                           const Eigen::Isometry3d& camera_T_world, MovedGhostFrame& out) {
  const std::uint64_t key = key_of(q);
  bool read_any = false, seen_any = false;
  for (std::size_t m = 0; m < objects_.size(); ++m) {
    Tracked& object = objects_[m];
    const auto it = object.index.find(key);
    if (it == object.index.end()) continue;
    Cell& cell = object.cells[it->second];
    if (cell.occupied_at == frame) continue;  // the object's place now: not a ghost of it
    read_any = true;
    // The camera looking through the ghost point itself shows the cell empty too (its centre
    // may lie just outside the image while the ghost is inside).
    if (cell.seen_empty_at < 0 && seen_through(q, depth, camera_T_world)) mark_seen(object, cell, frame);
    if (cell.seen_empty_at < 0) {
      ++out.objects[m].unseen;
      continue;
    }
    ++out.objects[m].seen;
    seen_any = true;
    object.worst_age = std::max(object.worst_age, frame - cell.seen_empty_at);
  }
  out.bins += read_any;
  out.seen_bins += seen_any;
}

MovedGhostFrame MovedGhosts::add_frame(int frame, const std::vector<std::optional<Eigen::Isometry3d>>& poses,
                                       const Circle& estimate, const Circle& truth, const Frame& depth,
                                       const Eigen::Isometry3d& world_T_camera) {
  check_input(frame, poses.size(), estimate, truth, depth);
  const Eigen::Isometry3d camera_T_world = world_T_camera.inverse();
  for (std::size_t m = 0; m < objects_.size(); ++m) {
    Tracked& object = objects_[m];
    // Readings of the previous frame end, at the latest, at this frame.
    if (object.worst_age >= 0) object.open_worst = std::max(object.open_worst, object.worst_age + frame - last_frame_);
    object.worst_age = -1;
    if (poses[m]) occupy(object, *poses[m], frame);
    look_through(object, depth, camera_T_world, frame);
  }
  MovedGhostFrame out;
  out.objects.resize(objects_.size());
  for (int b = 0; b < estimate.size(); ++b) {
    const Eigen::Vector3d q = estimate.bins[b].point.cast<double>();
    if (is_ghost(estimate.bins[b], truth.bins[b], config_.tolerance) && q.allFinite())
      read_bin(q, frame, depth, camera_T_world, out);
  }
  for (std::size_t m = 0; m < objects_.size(); ++m) {
    MovedObjectClearing& r = objects_[m].result;
    r.ghost_bins_at_end = out.objects[m].seen;
    r.unseen_ghost_bins_at_end = out.objects[m].unseen;
    r.max_ghost_bins = std::max(r.max_ghost_bins, out.objects[m].seen);
    r.ghost_frames += out.objects[m].seen > 0;
  }
  last_frame_ = frame;
  return out;
}

std::vector<MovedObjectClearing> MovedGhosts::results() const {
  std::vector<MovedObjectClearing> out;
  for (const Tracked& object : objects_) {
    MovedObjectClearing r = object.result;
    r.clearing_frames.reset();
    if (r.seen_empty_frame && object.worst_age < 0) r.clearing_frames = object.open_worst;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace sonomap::eval
