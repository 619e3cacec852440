// SPDX-License-Identifier: GPL-3.0-or-later
// An RGB picture in memory for the video's frames, with the few drawing steps they need
// (rectangles, lines, dots, text in a small built-in 5x7 bitmap font: no font files needed).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sonomap::harness {

using Rgb = std::array<std::uint8_t, 3>;

// Range colours shared by the video's panels: the diverging palette of the gnuplot pictures
// (harness/report/pictures.cpp), red near, blue far; t in [0, 1].
Rgb range_colour(double t);

class Canvas {
 public:
  Canvas(int width, int height, Rgb background);
  int width() const { return width_; }
  int height() const { return height_; }
  // Row-major RGB24, top row first: what ffmpeg's rawvideo rgb24 input reads.
  const std::vector<std::uint8_t>& pixels() const { return pixels_; }
  Rgb at(int x, int y) const;

  void set(int x, int y, Rgb colour);  // outside the canvas: ignored
  void fill_rect(int x, int y, int w, int h, Rgb colour);
  void line(double x0, double y0, double x1, double y1, Rgb colour);
  void dot(double x, double y, int radius, Rgb colour);
  // Text in the built-in font, `scale` pixels per font pixel, top-left at (x, y). Letters are
  // drawn upper case; characters the font lacks show as '?'. Returns the x after the text.
  int text(int x, int y, const std::string& s, Rgb colour, int scale = 2);
  static int text_width(const std::string& s, int scale = 2);

 private:
  int width_, height_;
  std::vector<std::uint8_t> pixels_;
};

}  // namespace sonomap::harness
