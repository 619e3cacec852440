// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/frame_source.hpp"

#include "harness/formats/scenario_yaml.hpp"
#include "harness/formats/sequence_io.hpp"
#include "harness/support/errors.hpp"
#include "sim/primitives.hpp"
#include "sim/simulation.hpp"
#include "sim/trajectory.hpp"
#include "sim/world_geometry.hpp"

#include <algorithm>
#include <stdexcept>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

class SimulatedSource final : public FrameSource {
 public:
  SimulatedSource(sim::Scenario scenario, const fs::path& file)
      : scenario_(std::move(scenario)), inputs_(scenario_inputs(scenario_, file)) {
    try {
      simulation_ = std::make_unique<sim::Simulation>(scenario_);
    } catch (const std::invalid_argument& e) {
      throw InputError(file.string() + ": " + e.what());
    }
  }
  std::string name() const override { return scenario_.name; }
  int frame_count() const override { return simulation_->frame_count(); }
  SourceFrame frame(int i) override {
    const Eigen::Isometry3d world_T_body_true = simulation_->true_body_pose(simulation_->time_of(i));
    return {simulation_->render(i), world_T_body_true};
  }
  double ground_z() const override { return scenario_.ground_z; }
  std::optional<sim::HeadSpec> head() const override { return scenario_.head; }
  std::uint64_t seed() const override { return scenario_.seed; }
  std::optional<std::vector<sim::WorldTriangle>> truth(double t) const override {
    return sim::world_triangles(scenario_, t);
  }
  std::vector<eval::MovingObjectShape> moving_objects() const override {
    std::vector<eval::MovingObjectShape> out;
    for (const sim::MovingObject& mover : scenario_.movers) {
      Eigen::AlignedBox3d box;
      for (const Eigen::Vector3f& v : sim::mesh_of(mover.shape, mover.mesh).vertices) box.extend(v.cast<double>());
      out.push_back({mover.name, box});
    }
    return out;
  }
  std::vector<std::optional<Eigen::Isometry3d>> moving_poses(double t) const override {
    std::vector<std::optional<Eigen::Isometry3d>> out;
    for (const sim::MovingObject& mover : scenario_.movers)
      out.push_back(sim::is_present(mover, t) ? std::optional(sim::pose_at(mover.trajectory, t)) : std::nullopt);
    return out;
  }
  std::vector<fs::path> inputs() const override { return inputs_; }

 private:
  sim::Scenario scenario_;
  std::vector<fs::path> inputs_;
  std::unique_ptr<sim::Simulation> simulation_;
};

// A recording (a TUM RGB-D folder or a sequence file): its poses are what a localisation
// system gave, its world turned z-up with the floor where the sequence file puts it; its truth
// the sequence file's reference cloud or mesh, if any.
class RecordedSource final : public FrameSource {
 public:
  RecordedSource(const fs::path& input, int frames)
      : sequence_(open_recorded_sequence(input)), input_(input) {
    count_ = sequence_->frame_count();
    if (frames > 0) count_ = std::min(count_, frames);
  }
  std::string name() const override { return sequence_->name(); }
  int frame_count() const override { return count_; }
  // The recorded pose is all there is: it stands for the truth as well.
  SourceFrame frame(int i) override {
    Frame frame = sequence_->frame(i);
    const Eigen::Isometry3d world_T_body = frame.world_T_body;
    return {std::move(frame), world_T_body};
  }
  double ground_z() const override { return sequence_->ground_z(); }
  std::uint64_t seed() const override { return 0; }
  // The sequence file's reference (static), if it names one.
  std::optional<std::vector<sim::WorldTriangle>> truth(double) const override {
    if (const auto* mesh = sequence_->truth_mesh()) return *mesh;
    return std::nullopt;
  }
  const std::vector<Eigen::Vector3f>* truth_cloud() const override { return sequence_->truth_cloud(); }
  bool depth_images() const override { return sequence_->depth_images(); }
  std::string truth_note() const override {
    if (sequence_->truth_cloud())
      return "recorded data: minima over the reference cloud's points (truth.cloud; within its point "
             "spacing of exact wedge minima, docs/conventions.md)";
    if (sequence_->truth_mesh()) return "recorded data: exact wedge minima from the reference mesh (truth.mesh)";
    return {};
  }
  std::vector<fs::path> inputs() const override { return {input_}; }

 private:
  std::unique_ptr<RecordedSequence> sequence_;
  fs::path input_;  // the folder or the sequence file
  int count_ = 0;
};

}  // namespace

std::vector<fs::path> scenario_inputs(const sim::Scenario& scenario, const fs::path& file) {
  std::vector<fs::path> files{file};
  for (const auto& object : scenario.statics)
    if (!object.shape.mesh_path.empty()) files.emplace_back(object.shape.mesh_path);
  for (const auto& object : scenario.movers)
    if (!object.shape.mesh_path.empty()) files.emplace_back(object.shape.mesh_path);
  return files;
}

std::unique_ptr<FrameSource> open_frame_source(const fs::path& input,
                                               std::vector<std::string> overrides, int frames,
                                               std::optional<std::uint64_t> seed) {
  if (fs::is_directory(input) || is_sequence_file(input)) {
    if (!overrides.empty())
      throw InputError("--set " + overrides.front() +
                       ": a recorded sequence has no scenario keys (only run keys apply)");
    return std::make_unique<RecordedSource>(input, frames);
  }
  if (frames > 0) overrides.push_back("frames=" + std::to_string(frames));
  if (seed) overrides.push_back("seed=" + std::to_string(*seed));
  return std::make_unique<SimulatedSource>(load_scenario(input, overrides), input);
}

}  // namespace sonomap::harness
