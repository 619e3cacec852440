// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/pictures.hpp"

#include "harness/support/output.hpp"
#include "harness/support/subprocess.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Display coordinates of a bearing theta (ccw from ahead) at range r: ahead is up, left is left.
void to_display(double theta_deg, double r, double& dx, double& dy) {
  const double t = theta_deg * kPi / 180.0;
  dx = -r * std::sin(t);
  dy = r * std::cos(t);
}

const char* kPalette =
    "set palette defined (0 '#b2182b', 1 '#ef8a62', 2 '#fddbc7', 3 '#d1e5f0', 4 '#67a9cf', "
    "5 '#2166ac')\n";

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

void draw_with_gnuplot(const fs::path& png, const std::string& script_text) {
  const fs::path script = fs::path(png).replace_extension(".gp");
  write_text_file(script, script_text);
  run_gnuplot(script);
  fs::remove(script);
}

void run_gnuplot(const fs::path& script) {
  std::string output;
  const int status = run_program({"gnuplot", script.string()}, &output);
  if (status != 0)
    throw std::runtime_error("gnuplot failed on " + script.string() + " (status " +
                             std::to_string(status) + "): " + output);
}

void plot_circle(const fs::path& png, const Circle& estimate, const Circle* truth,
                 const RasterOrigin& origin, const RasterConfig& config,
                 const std::string& title) {
  const int bins = static_cast<int>(estimate.bins.size());
  const double bin_deg = 360.0 / bins;
  const double ring = config.max_range * 1.08;
  std::ostringstream gp;
  gp.precision(6);
  gp << "set terminal pngcairo size 900,900 noenhanced font 'DejaVu Sans,11'\n"
     << "set output " << quoted(png.string()) << "\n"
     << "set title " << quoted(title) << "\n"
     << "set size ratio -1\nset grid\n"
     << "set xlabel 'right (m)   [left is left, ahead is up]'\nset ylabel 'ahead (m)'\n"
     << "set xrange [" << -ring * 1.1 << ":" << ring * 1.1 << "]\n"
     << "set yrange [" << -ring * 1.1 << ":" << ring * 1.1 << "]\n"
     << kPalette << "set cbrange [0:" << config.max_range << "]\nset cblabel 'range (m)'\n";

  // Ring: one short arc per bin, coloured by its range; unknown bins in grey.
  gp << "$ring << EOD\n";
  for (int k = 0; k < bins; ++k) {
    const RasterCell& c = estimate.bins[k];
    if (!c.known()) continue;
    for (double a : {k * bin_deg, (k + 1) * bin_deg}) {
      double x, y;
      to_display(a, ring, x, y);
      gp << x << ' ' << y << ' ' << c.range << '\n';
    }
    gp << "\n";
  }
  gp << "EOD\n$unknown << EOD\n";
  for (int k = 0; k < bins; ++k) {
    if (estimate.bins[k].known()) continue;
    for (double a : {k * bin_deg, (k + 1) * bin_deg}) {
      double x, y;
      to_display(a, ring, x, y);
      gp << x << ' ' << y << '\n';
    }
    gp << "\n";
  }
  // Selected closest points, in the listener's frame.
  gp << "EOD\n$points << EOD\n";
  const double c = std::cos(-origin.heading), s = std::sin(-origin.heading);
  for (const RasterCell& cell : estimate.bins) {
    if (!cell.known() || !cell.point.allFinite()) continue;
    const double wx = cell.point.x() - origin.position.x(), wy = cell.point.y() - origin.position.y();
    const double bx = c * wx - s * wy, by = s * wx + c * wy;  // body x ahead, y left
    gp << -by << ' ' << bx << ' ' << cell.range << '\n';
  }
  gp << "EOD\n$truth << EOD\n";
  if (truth) {
    for (int k = 0; k <= bins; ++k) {
      const RasterCell& cell = truth->bins[k % bins];
      if (!cell.known()) {
        gp << "\n";
        continue;
      }
      double x, y;
      to_display((k % bins + 0.5) * bin_deg + (k == bins ? 360.0 : 0.0), cell.range, x, y);
      gp << x << ' ' << y << '\n';
    }
  }
  gp << "EOD\n"
     << "set object 1 circle at 0,0 size 0.08 fc rgb 'black' fs solid\n"
     << "set arrow 1 from 0,0 to 0,0.5 lw 2 lc rgb 'black'\n"
     << "plot $unknown using 1:2 with lines lw 10 lc rgb '#cccccc' title 'not yet scanned', \\\n"
     << "     $ring using 1:2:3 with lines lw 10 lc palette notitle, \\\n"
     << "     $truth using 1:2 with lines lw 1.5 lc rgb 'black' title 'ground truth', \\\n"
     << "     $points using 1:2:3 with points pt 7 ps 0.7 lc palette title 'closest points'\n";

  draw_with_gnuplot(png, gp.str());
}

void plot_edf_arrows(const fs::path& png, const Circle& map_circle, const EdfRaster& edf,
                     const RasterOrigin& origin, const RasterConfig& config,
                     const std::string& title, double arrow_step_deg) {
  const int bins = map_circle.size();
  if (bins == 0 || static_cast<int>(edf.bins.size()) != bins || edf.traced.size() != bins)
    throw std::invalid_argument("plot_edf_arrows: the map circle and the EDF circle differ in bins");
  const int stride = std::max(1, static_cast<int>(std::lround(arrow_step_deg * bins / 360.0)));
  // World direction -> display (body frame: x ahead is up, y left is left).
  const double c = std::cos(-origin.heading), s = std::sin(-origin.heading);
  auto display = [&](double wx, double wy, double& dx, double& dy) {
    const double bx = c * wx - s * wy, by = s * wx + c * wy;
    dx = -by;
    dy = bx;
  };
  const double extent = config.max_range * 1.1;
  std::ostringstream gp;
  gp.precision(6);
  gp << "set terminal pngcairo size 1600,820 noenhanced font 'DejaVu Sans,11'\n"
     << "set output " << quoted(png.string()) << "\n"
     << "set size ratio -1\nset grid\n"
     << "set xrange [" << -extent << ":" << extent << "]\nset yrange [" << -extent << ":" << extent << "]\n"
     << "set xlabel 'right (m)   [left is left, ahead is up]'\nset ylabel 'ahead (m)'\n"
     << "set object 1 circle at 0,0 size 0.08 fc rgb 'black' fs solid front\n";
  gp << "$rays << EOD\n";
  for (int k = 0; k < bins; k += stride) {
    const RasterCell& cell = map_circle.bins[k];
    if (!cell.known()) continue;
    double x, y;
    to_display(map_circle.bin_centre_deg(k), cell.range, x, y);
    gp << "0 0 " << x << ' ' << y << '\n';
  }
  gp << "EOD\n$ring << EOD\n";
  for (int k = 0; k < bins; ++k) {
    if (!map_circle.bins[k].known()) continue;
    double x, y;
    to_display(map_circle.bin_centre_deg(k), map_circle.bins[k].range, x, y);
    gp << x << ' ' << y << '\n';
  }
  gp << "EOD\n$arrows << EOD\n";
  for (int k = 0; k < bins; k += stride) {
    const EdfBin& b = edf.bins[k];
    if (!b.sample_observed) continue;
    double x, y, dx, dy;
    display(b.sample_point.x() - origin.position.x(), b.sample_point.y() - origin.position.y(), x, y);
    display(b.sample_distance * b.closest_direction.x(), b.sample_distance * b.closest_direction.y(), dx, dy);
    gp << x << ' ' << y << ' ' << dx << ' ' << dy << '\n';
  }
  gp << "EOD\n$samples << EOD\n";
  for (const EdfBin& b : edf.bins) {
    double x, y;
    display(b.sample_point.x() - origin.position.x(), b.sample_point.y() - origin.position.y(), x, y);
    gp << x << ' ' << y << ' ' << (b.sample_observed ? 1 : 0) << '\n';
  }
  gp << "EOD\n$traced << EOD\n";
  for (int k = 0; k < bins; ++k) {
    if (!edf.traced.bins[k].known()) continue;
    double x, y;
    to_display(edf.traced.bin_centre_deg(k), edf.traced.bins[k].range, x, y);
    gp << x << ' ' << y << '\n';
  }
  gp << "EOD\n"
     << "set multiplot layout 1,2 title " << quoted(title) << "\n"
     << "set title 'circle: the closest range along each bearing (rays)'\n"
     << "plot $ring using 1:2 with points pt 7 ps 0.5 lc rgb 'black' title 'map circle', \\\n"
     << "     $rays using 1:2:3:4 with vectors head filled size 0.08,20 lw 1.5 lc rgb '#2166ac' "
        "title 'ray bearings'\n"
     << "set title 'EDF: distance and direction to the closest surface (-gradient)'\n"
     << "plot $traced using 1:2 with points pt 7 ps 0.5 lc rgb '#999999' title 'sphere-traced ranges', \\\n"
     << "     $samples using 1:2:($3 > 0 ? 0x000000 : 0xcccccc) with points pt 7 ps 0.4 lc rgb variable "
        "title 'query points', \\\n"
     << "     $arrows using 1:2:3:4 with vectors head filled size 0.08,20 lw 1.5 lc rgb '#2166ac' "
        "title 'gradient bearings'\n"
     << "unset multiplot\n";
  draw_with_gnuplot(png, gp.str());
}

void plot_cylinder(const fs::path& png, const Cylinder& estimate, const RasterConfig& config,
                   const std::string& title) {
  const int bins = estimate.azimuth_bins;
  const double bin_deg = 360.0 / bins;
  std::ostringstream gp;
  gp.precision(6);
  gp << "set terminal pngcairo size 1200,420 noenhanced font 'DejaVu Sans,11'\n"
     << "set output " << quoted(png.string()) << "\n"
     << "set title " << quoted(title) << "\n"
     << "set xlabel 'azimuth (deg, + is left)'\nset ylabel 'height above ground (m)'\n"
     << "set xrange [180:-180]\nset xtics 45\n"
     << "set yrange [" << config.band_min << ":" << config.band_max << "]\n"
     << kPalette << "set cbrange [0:" << config.max_range << "]\nset cblabel 'range (m)'\n"
     << "$cells << EOD\n";
  // One line per cell centre: azimuth in (-180, 180] so ahead sits in the middle.
  for (int row = 0; row < estimate.rows; ++row) {
    const double z = config.band_min + (row + 0.5) * config.row_height;
    for (int k = 0; k < bins; ++k) {
      double a = (k + 0.5) * bin_deg;
      if (a > 180.0) a -= 360.0;
      const RasterCell& cell = estimate.at(row, k);
      if (cell.known()) gp << a << ' ' << z << ' ' << cell.range << '\n';
    }
  }
  gp << "EOD\n"
     << "plot $cells using 1:2:(" << bin_deg / 2 << "):(" << config.row_height / 2
     << "):3 with boxxyerror fs solid noborder lc palette notitle\n";
  draw_with_gnuplot(png, gp.str());
}

}  // namespace sonomap::harness
