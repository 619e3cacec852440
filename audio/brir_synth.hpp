// SPDX-License-Identifier: GPL-3.0-or-later
// Binaural room impulse responses of a shoebox room, synthesised from a measured HRIR set:
// image sources (Allen & Berkley 1979) up to a given reflection order, each rendered with the
// HRIR of its arrival direction in the head frame, delayed by r/c (fractional delay) and
// scaled by the wall reflection product / r; after the mixing time an exponentially decaying,
// interaurally decorrelated noise tail (per octave band) with the room's RT60.
#pragma once

#include "audio/brir_set.hpp"

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace sonomap::audio {

// A rectangular room spanning [min_corner, max_corner] (metres, world axes, z up).
struct ShoeboxRoom {
  Eigen::Vector3d min_corner = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_corner = Eigen::Vector3d(5.0, 4.0, 3.0);
  Eigen::Vector3d size() const { return max_corner - min_corner; }
  double volume() const;
  double surface() const;
};

// Uniform wall absorption <-> RT60. Sabine: T = 0.161 V / (S a); Eyring: T = 0.161 V /
// (-S ln(1 - a)). Eyring is the one used by the synthesiser (valid for absorptive rooms too).
double sabine_rt60(const ShoeboxRoom& room, double absorption);
double sabine_absorption(const ShoeboxRoom& room, double rt60);
double eyring_rt60(const ShoeboxRoom& room, double absorption);
double eyring_absorption(const ShoeboxRoom& room, double rt60);

// Octave bands of the late tail (centre frequencies, Hz).
const std::vector<double>& octave_band_centres();  // 125 .. 8000 Hz, 7 bands

struct BrirSynthConfig {
  ShoeboxRoom room;
  // Head position; empty (NaN) means the room centre at 1.5 m above the floor (or mid-height
  // in a room lower than 3 m).
  Eigen::Vector3d listener = Eigen::Vector3d::Constant(NAN);
  double listener_heading_deg = 0.0;  // direction the listener faces (0 = +x)
  double rt60 = 0.5;                  // seconds; sets the wall absorption (Eyring)
  std::vector<double> band_rt60;      // per octave band; empty: rt60 in every band
  int max_order = 3;                  // image-source reflection order
  double sample_rate = 48000.0;       // the HRIR set must already be at this rate
  double length_s = 0.0;              // IR length; 0: the largest RT60 (60 dB of decay)
  double speed_of_sound = 343.0;
  double wall_margin = 0.5;  // a source beyond a wall pushes that wall to this far behind it
  bool late_tail = true;
  uint64_t seed = 1;  // tail noise (one stream per source direction and ear)
};

// What a room may be. Outside these the image-source model stops describing a room a person
// stands in (a 0.2 m box puts image sources a few centimetres from the ears, +40 dBFS before
// normalisation; a 1e300 m one loses the listener's position to rounding), or the set would
// not fit in memory (2400 responses of up to 3 s).
struct RoomBounds {
  double min_side_m = 1.0;
  double max_side_m = 500.0;
  double max_coordinate_m = 10000.0;   // corners within 10 km of the origin
  double min_wall_distance_m = 0.25;   // listener to every wall, floor and ceiling
  double max_rt60_s = 3.0;             // also the longest IR (--ir-length)
};
inline constexpr RoomBounds kRoomBounds{};

// Validates the config (room within kRoomBounds, listener inside, RT60, order >= 0, ...),
// throws std::invalid_argument naming the offending value.
void validate(const BrirSynthConfig& config);

// The listener position the config resolves to.
Eigen::Vector3d listener_position(const BrirSynthConfig& config);

// Synthesises BRIR sets for one room. The late tail is noise of its own for every source
// direction and ear (a shared tail would give every response the same spectral quirks and the
// same left/right lean), balanced so both ears get the same energy in every twelfth of an
// octave and every ~43 ms.
class BrirSynthesizer {
 public:
  BrirSynthesizer(HrirSet hrirs, BrirSynthConfig config);  // keeps its own copy

  // The BRIR pair of a source at `azimuth_deg` (head frame, counter-clockwise from ahead) and
  // horizontal `distance_m` from the head, at ear height.
  BinauralIr synthesize(double azimuth_deg, double distance_m) const;
  // A caller's "give up now" test, polled before each grid point (e.g. a pending signal); once
  // it returns true the remaining points are skipped and an empty set is returned.
  using StopRequested = std::function<bool()>;

  // The whole grid (parallel over grid points; the result does not depend on thread count).
  BrirSet synthesize(const BrirGrid& grid, const StopRequested& stop = {}) const;

  // The whole grid made on demand: the same responses as synthesize(grid) followed by
  // BrirSet::normalise_to_reference(), but only the points looked up stay in memory. Every
  // point is synthesised once here for the reference level (in parallel, two at a time in
  // memory per thread) and again on its first lookup. `self` must own this synthesiser.
  static BrirSet synthesize_on_demand(std::shared_ptr<const BrirSynthesizer> self, const BrirGrid& grid,
                                      const StopRequested& stop = {});

  size_t length() const { return length_; }
  double absorption() const { return absorption_; }
  // std::invalid_argument unless the source is finite, in (0.05, 500] m and its direct sound
  // fits in the IR length (synthesize checks this too).
  void check_source(double azimuth_deg, double distance_m) const;
  // The shortest IR length that holds the whole direct sound of a source this far away.
  double min_length_s(double distance_m) const {
    return double(direct_end(distance_m)) / config_.sample_rate;
  }

 private:
  size_t direct_end(double distance_m) const;  // samples

  BinauralIr late_tail(double azimuth_deg, double distance_m, size_t start) const;

  HrirSet hrirs_;
  BrirSynthConfig config_;
  Eigen::Vector3d listener_;
  size_t length_ = 0;
  double absorption_ = 0.0;
  double tail_level_ = 0.0;        // diffuse-field amplitude at t = 0
  struct TailShape;  // what every late tail shares (brir_synth.cpp)
  std::shared_ptr<const TailShape> tail_shape_;
};

}  // namespace sonomap::audio
