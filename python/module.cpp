// SPDX-License-Identifier: GPL-3.0-or-later
// The `sonomap` Python module (docs/python.md): scenarios with overrides, frames as numpy
// arrays, the exact ground truth, the metrics, the built-in mappers and sweeps, all through
// the C++ libraries `run` uses. Long calls release the GIL.
#include "harness/app/mapper_factory.hpp"
#include "harness/app/mapper_registry.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/output.hpp"
#include "python/arrays.hpp"
#include "python/scene.hpp"
#include "python/sweep.hpp"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

namespace py = pybind11;
using namespace sonomap;
using namespace sonomap::python;

namespace {

using Release = py::call_guard<py::gil_scoped_release>;

// A frame with its arrays made on first use.
struct PyFrame {
  std::shared_ptr<const SensedFrame> sensed;
  py::object depth, points;
  const Frame& frame() const { return sensed->sensed.frame; }
};

py::dict metrics_dict(const eval::RasterMetrics& m) {
  py::dict d;
  d["coverage"] = m.coverage;
  d["rmse"] = m.rmse;
  d["rmse_off_edges"] = m.rmse_off_edges;
  d["ghosts"] = m.ghosts;
  d["cells"] = m.cells;
  d["truth_occupied"] = m.truth_occupied;
  d["estimate_known"] = m.estimate_known;
  d["known_in_both"] = m.known_in_both;
  d["edge_cells"] = m.edge_cells;
  return d;
}

py::dict raster_dict(const RasterConfig& r) {
  py::dict d;
  d["azimuth_bins"] = r.azimuth_bins;
  d["band_min"] = r.band_min;
  d["band_max"] = r.band_max;
  d["row_height"] = r.row_height;
  d["rows"] = r.rows();
  d["max_range"] = r.max_range;
  return d;
}

py::dict intrinsics_dict(const Frame& f) {
  py::dict d;
  d["fx"] = f.intrinsics.fx;
  d["fy"] = f.intrinsics.fy;
  d["cx"] = f.intrinsics.cx;
  d["cy"] = f.intrinsics.cy;
  d["width"] = f.width;
  d["height"] = f.height;
  return d;
}

// "key=value" strings from a dict {key: value} (bools as true/false) or a list of strings.
std::vector<std::string> key_values(const py::object& settings) {
  std::vector<std::string> out;
  if (settings.is_none()) return out;
  if (!py::isinstance<py::dict>(settings)) return settings.cast<std::vector<std::string>>();
  for (const auto& [key, value] : settings.cast<py::dict>()) {
    std::string text = py::str(value);
    if (py::isinstance<py::bool_>(value)) text = value.cast<bool>() ? "true" : "false";
    out.push_back(py::str(key).cast<std::string>() + "=" + text);
  }
  return out;
}

void bind_frame(py::module_& m) {
  py::class_<PyFrame>(m, "Frame", "One sensed frame: what a mapper gets, and the true body pose.")
      .def_property_readonly("index", [](const PyFrame& f) { return f.frame().index; })
      .def_property_readonly("time", [](const PyFrame& f) { return f.frame().time; }, "seconds")
      .def_property_readonly("width", [](const PyFrame& f) { return f.frame().width; })
      .def_property_readonly("height", [](const PyFrame& f) { return f.frame().height; })
      .def_property_readonly("intrinsics", [](const PyFrame& f) { return intrinsics_dict(f.frame()); },
                             "dict fx, fy, cx, cy (pixels), width, height")
      .def_property_readonly("depth", [](PyFrame& f) {
            if (!f.depth) f.depth = depth_array(f.frame());
            return f.depth;
          }, "(height, width) float32 z-depth in metres; NaN where there is no return")
      .def_property_readonly("points", [](PyFrame& f) {
            if (!f.points) f.points = points_array(f.frame());
            return f.points;
          }, "(N, 3) float32: the valid returns in the camera optical frame (x right, y down, z forward)")
      .def_property_readonly("world_T_camera", [](const PyFrame& f) { return matrix_array(f.frame().world_T_camera); },
                             "4x4: camera optical frame to world, the localisation estimate the mapper gets")
      .def_property_readonly("world_T_body", [](const PyFrame& f) { return matrix_array(f.frame().world_T_body); },
                             "4x4: body (listener) frame to world, estimated; rasters are centred on it")
      .def_property_readonly("world_T_body_true", [](const PyFrame& f) { return matrix_array(f.sensed->sensed.world_T_body_true); },
                             "4x4: the true body pose (the ground truth is seen from it; not for mappers)")
      .def_property_readonly("heading", [](const PyFrame& f) { return heading_of(f.frame().world_T_body); },
                             "radians: yaw of the estimated body x axis, the raster's bin 0 direction")
      .def("__repr__", [](const PyFrame& f) {
        return "<sonomap.Frame " + std::to_string(f.frame().index) + " t=" + std::to_string(f.frame().time) + ">";
      });
}

void bind_rasters(py::module_& m) {
  py::class_<Rasters>(m, "Rasters", "A circle and a cylinder; ranges in metres, NaN = unknown.")
      .def_property_readonly("circle", [](const Rasters& r) { return circle_array(r.circle); },
                             "(azimuth_bins,) float64, bin k = azimuths [k, k+1) x bin width, "
                             "counter-clockwise from the heading")
      .def_property_readonly("cylinder", [](const Rasters& r) { return cylinder_array(r.cylinder); },
                             "(rows, azimuth_bins) float64, row 0 at the bottom of the obstacle band");
}

py::dict score(const Scene& scene, const PyFrame& frame, const DoubleArray& circle_ranges,
               const std::optional<DoubleArray>& cylinder_ranges) {
  const Circle circle = circle_from_array(circle_ranges, scene.raster());
  std::optional<Cylinder> cylinder;
  if (cylinder_ranges) cylinder = cylinder_from_array(*cylinder_ranges, scene.raster());
  eval::FrameEvaluation e;
  {
    py::gil_scoped_release release;
    e = scene.score(*frame.sensed, circle, cylinder ? &*cylinder : nullptr);
  }
  py::dict d;
  d["circle"] = metrics_dict(e.circle);
  if (cylinder) d["cylinder"] = metrics_dict(e.cylinder);
  return d;
}

void bind_scenario(py::module_& m) {
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scenario",
      "A scenario YAML file (or a recorded sequence) with overrides, as `sonomap run` loads it.")
      .def(py::init<const std::filesystem::path&, const std::vector<std::string>&, int,
                    std::optional<std::uint64_t>>(),
           py::arg("path"), py::arg("overrides") = std::vector<std::string>{}, py::arg("frames") = 0,
           py::arg("seed") = py::none(), Release(),
           "overrides: 'key=value' as --set (scenario keys, raster.*, metrics.*, mapper.*); "
           "frames > 0 and seed override the scenario's. Raises InputError naming file, line and key.")
      .def_property_readonly("name", &Scene::name)
      .def_property_readonly("frame_count", &Scene::frame_count)
      .def_property_readonly("seed", &Scene::seed)
      .def_property_readonly("ground_z", &Scene::ground_z, "metres: the floor the obstacle band is measured from")
      .def_property_readonly("has_truth", &Scene::has_truth)
      .def_property_readonly("raster", [](const Scene& s) { return raster_dict(s.raster()); })
      .def_property_readonly("metrics", [](const Scene& s) {
        return py::dict(py::arg("ghost_tolerance") = s.metrics().ghost_tolerance,
                        py::arg("edge_jump") = s.metrics().edge_jump);
      })
      .def("__len__", &Scene::frame_count)
      .def("__getitem__", [](Scene& s, int i) {
            if (i < 0) i += s.frame_count();
            std::shared_ptr<const SensedFrame> f;
            {
              py::gil_scoped_release release;
              f = s.frame(i);
            }
            return PyFrame{std::move(f), {}, {}};
          }, "Frame i (negative: from the end); rendered on demand, the same in any order")
      .def("truth", [](const Scene& s, const PyFrame& f) {
            py::gil_scoped_release release;
            return s.truth(*f.sensed);
          }, py::arg("frame"), "The exact ground-truth Rasters at the frame's time and true body pose")
      .def("score", &score, py::arg("frame"), py::arg("circle"), py::arg("cylinder") = py::none(),
           "The metrics `run` writes (dict per raster: coverage, rmse, rmse_off_edges, ghosts, ...) "
           "of a circle (and cylinder) against the frame's ground truth")
      .def("mapper", [](std::shared_ptr<Scene> s, const std::string& name, double voxel, const py::object& settings) {
            const std::vector<std::string> entries = key_values(settings);
            py::gil_scoped_release release;
            return std::make_unique<MapperSession>(s, s->make_mapper(name, voxel, entries));
          }, py::arg("name") = "vdb_gpdf", py::arg("voxel") = 0.0, py::arg("settings") = py::none(),
          "A built-in mapper (sonomap.mapper_names()) with the scenario's mapper.* overrides and "
          "`settings` (dict or 'key=value' list); voxel 0: the mapper's default");
}

void bind_mapper(py::module_& m) {
  py::class_<MapperSession>(m, "Mapper", "A mapper fed frame by frame (Scenario.mapper makes one).")
      .def_property_readonly("name", [](const MapperSession& s) { return s.mapper().name(); })
      .def_property_readonly("config", [](const MapperSession& s) {
        py::dict d;
        for (const auto& [key, value] : harness::mapper_config_entries(s.mapper())) d[py::str(key)] = value;
        return d;
      }, "the mapper's settings as summary.json records them")
      .def("integrate", [](MapperSession& s, const PyFrame& f) { s.integrate(*f.sensed); }, py::arg("frame"),
           Release(), "Fuses the frame (its points at its estimated camera pose)")
      .def("rasters", [](MapperSession& s, const PyFrame& f) { return s.rasters(*f.sensed); }, py::arg("frame"),
           Release(), "The map's circle and cylinder around the frame's estimated body pose");
}

harness::SonifySetup sweep_setup(const std::optional<std::filesystem::path>& brirs, const std::string& room,
                                 const std::vector<double>& listener, double heading, double rt60, int order,
                                 double ir_length, const std::optional<std::filesystem::path>& hrir,
                                 const std::string& mode, double period, const std::string& level,
                                 double loudness) {
  harness::SonifySetup s;
  if (brirs) s.brir_dir = *brirs;
  s.room.room = room;
  s.room.listener = listener;
  s.room.heading_deg = heading;
  s.room.rt60 = rt60;
  s.room.order = order;
  s.room.length_s = ir_length;
  if (hrir) s.room.hrir_file = *hrir;
  if (mode != "ranging" && mode != "objects")
    throw harness::InputError("option mode: expected 'ranging' or 'objects', got '" + mode + "'");
  s.sweep.mode = mode == "ranging" ? audio::SweepMode::Ranging : audio::SweepMode::Objects;
  if (level != "per-file" && level != "fixed")
    throw harness::InputError("option level: expected 'per-file' or 'fixed', got '" + level + "'");
  s.sweep.level = level == "fixed" ? audio::LevelMode::Fixed : audio::LevelMode::PerFile;
  s.sweep.period_s = period;
  s.sweep.loudness.target_lufs = loudness;
  return s;
}

py::array_t<float> stereo_array(const audio::SweepAudio& a) {
  py::array_t<float> out({static_cast<py::ssize_t>(a.left.size()), py::ssize_t{2}});
  float* p = out.mutable_data();
  for (size_t i = 0; i < a.left.size(); ++i) p[2 * i] = a.left[i], p[2 * i + 1] = a.right[i];
  return out;
}

py::dict level_dict(const audio::SweepAudio& a) {
  return py::dict(py::arg("gain_db") = a.gain_db, py::arg("loudness_lufs") = a.loudness.integrated_lufs,
                  py::arg("true_peak_dbtp") = a.loudness.true_peak_dbtp, py::arg("peak_limited") = a.peak_limited);
}

void bind_sweep(py::module_& m) {
  py::class_<SweepSession>(m, "Sweep",
      "The binaural sweep of a circle (as `sonomap sonify`): BRIRs from a directory, or "
      "synthesised once for a shoebox room")
      .def(py::init([](const std::optional<std::filesystem::path>& brirs, const std::string& room,
                       const std::vector<double>& listener, double heading, double rt60, int order,
                       double ir_length, const std::optional<std::filesystem::path>& hrir,
                       const std::string& mode, double period, const std::string& level, double loudness) {
             harness::SonifySetup setup = sweep_setup(brirs, room, listener, heading, rt60, order, ir_length,
                                                      hrir, mode, period, level, loudness);
             py::gil_scoped_release release;
             return std::make_unique<SweepSession>(std::move(setup));
           }),
           py::arg("brirs") = py::none(), py::arg("room") = "5x4x3",
           py::arg("listener") = std::vector<double>{}, py::arg("heading") = 0.0, py::arg("rt60") = 0.5,
           py::arg("order") = 3, py::arg("ir_length") = 0.0, py::arg("hrir") = py::none(),
           py::arg("mode") = "ranging", py::arg("period") = 2.0, py::arg("level") = "per-file",
           py::arg("loudness") = -16.0)
      .def_property_readonly("sample_rate", &SweepSession::sample_rate)
      .def("render", [](SweepSession& s, const DoubleArray& circle) {
            const Circle c = circle_from_array(circle);
            audio::SweepAudio a;
            {
              py::gil_scoped_release release;
              a = s.render(c);
            }
            return stereo_array(a);
          }, py::arg("circle"), "(samples, 2) float32 stereo at sample_rate; no sample above -1 dBFS")
      .def("write", [](SweepSession& s, const DoubleArray& circle, const std::filesystem::path& wav) {
            const Circle c = circle_from_array(circle);
            audio::SweepAudio a;
            {
              py::gil_scoped_release release;
              a = s.write(c, wav);
            }
            return level_dict(a);
          }, py::arg("circle"), py::arg("path"),
          "Writes the WAV and PATH.events.csv under sonomap's output rules; returns the level applied");
}

}  // namespace

PYBIND11_MODULE(sonomap, m) {
  m.doc() = "sonomap: scenarios, frames, exact ground truth, metrics, mappers and sweeps (docs/python.md)";
  m.attr("__version__") = SONOMAP_VERSION;
  py::register_exception<harness::InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<harness::WriteError>(m, "WriteError", PyExc_OSError);
  m.def("mapper_names", &harness::mapper_names, "The mappers Scenario.mapper accepts");
  bind_frame(m);
  bind_rasters(m);
  bind_scenario(m);
  bind_mapper(m);
  bind_sweep(m);
}
