// SPDX-License-Identifier: GPL-3.0-or-later
// Binaural impulse responses held in memory: a measured HRIR set (any directions) used to
// synthesise rooms, and a BRIR set on the paper's horizontal grid (azimuth x distance) used by
// the sweep. Directions follow SOFA and docs/conventions.md: x front, y left, z up, azimuth
// counter-clockwise from the front. Files are read and written by harness/sofa_io.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

namespace sonomap::audio {

enum class Ear { Left = 0, Right = 1 };

// One impulse response per ear, equal lengths.
struct BinauralIr {
  std::vector<float> left;
  std::vector<float> right;
  const std::vector<float>& ear(Ear e) const { return e == Ear::Left ? left : right; }
};

// A measured free-field HRIR set: one binaural IR per direction.
struct HrirSet {
  double sample_rate = 0.0;
  std::vector<Eigen::Vector3d> directions;  // unit vectors in the head frame
  std::vector<BinauralIr> irs;              // irs[i] measured from directions[i]
  // Index of the measured direction closest in angle to `direction` (any length > 0).
  size_t nearest(const Eigen::Vector3d& direction) const;
  // Throws std::invalid_argument unless non-empty, consistent and finite.
  void validate() const;
};

// The paper's BRIR grid: azimuth every 3 degrees over -177..180, distances 0.4..4.0 m by 0.4 m.
struct BrirGrid {
  std::vector<double> azimuths_deg;
  std::vector<double> distances_m;
  static BrirGrid paper();
};

// BRIRs on a grid; irs[d * azimuths + a] is the pair for distances_m[d], azimuths_deg[a].
// No interpolation anywhere: lookups snap to the nearest measured azimuth and distance.
class BrirSet {
 public:
  BrirSet() = default;
  BrirSet(double sample_rate, BrirGrid grid, std::vector<BinauralIr> irs);
  // A set whose responses are made on first lookup by make(distance index, azimuth index), each
  // of ir_length samples per ear, and kept: memory for the points that are played only.
  // Lookups may come from several threads (each point is made once).
  using MakeIr = std::function<BinauralIr(size_t distance_index, size_t azimuth_index)>;
  BrirSet(double sample_rate, BrirGrid grid, size_t ir_length, MakeIr make);

  double sample_rate() const { return sample_rate_; }
  const BrirGrid& grid() const { return grid_; }
  size_t azimuth_count() const { return grid_.azimuths_deg.size(); }
  size_t distance_count() const { return grid_.distances_m.size(); }
  size_t ir_length() const { return ir_length_; }
  bool empty() const { return irs_.empty(); }
  size_t made_count() const;  // responses held in memory (all of them unless made on demand)

  size_t nearest_azimuth(double azimuth_deg) const;  // circular distance, any angle
  size_t nearest_distance(double metres) const;
  const BinauralIr& at(size_t distance_index, size_t azimuth_index) const;

  // Scales the set to the reference level every set is played at: its loudest response (one
  // ear at one grid point, energy = sum of squared samples) gets unit energy, so sets from
  // different rooms, HRIRs or files start from the same level. Returns the factor applied
  // (1 for an all-zero set). A set made on demand must be normalised by its maker instead
  // (throws std::logic_error).
  double normalise_to_reference();

 private:
  double sample_rate_ = 0.0;
  BrirGrid grid_;
  mutable std::vector<BinauralIr> irs_;  // mutable: a set made on demand fills it in at()
  size_t ir_length_ = 0;
  // Made on demand: the maker, and one flag per grid point (its response is in irs_ once set).
  MakeIr make_;
  std::unique_ptr<std::once_flag[]> made_;
};

// The reference level's pieces (normalise_to_reference): the larger of the two ears' energies
// (sum of squared samples), and every sample times `factor`.
double loudest_ear_energy(const BinauralIr& ir);
void scale(BinauralIr& ir, double factor);

// Angle difference a - b wrapped to (-180, 180].
double wrap_degrees_180(double degrees);

// Index of the value nearest to `metres` (values non-empty). A value within 1 um of a midpoint
// is a tie (grid values may come from float files or sums like 3 x 0.4), and a tie goes to
// the larger distance, as ordinary rounding does: 1.0 m on a 0.4 m grid plays 1.2 m.
size_t nearest_distance_index(const std::vector<double>& values, double metres);
// Index of the azimuth nearest to `degrees` on the circle (ties: the first listed).
size_t nearest_azimuth_index(const std::vector<double>& values, double degrees);

}  // namespace sonomap::audio
