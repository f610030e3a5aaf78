// PNG input/output (libpng).
//
// Image convention: an RGB buffer passed to write_png_rgb has row 0 at the TOP of the image
// (the PNG file order). Field and GreyImage data use the simulation convention instead:
// index i + width*j with j = 0 the BOTTOM row (y up); the functions here do the flip.
//
// Errors: every failure (file cannot be opened, not a PNG, corrupt or truncated data, disk
// full, rename failed) throws morphogen::UserError with a one-line message naming the path and
// the reason. Writes go to `path + ".tmp"` and are renamed onto `path` only when complete, so a
// failed write never leaves a partial file at `path` (the .tmp file is removed).
#pragma once

#include "io/colormap.hpp"

#include <string>
#include <vector>

namespace morphogen::io {

// Write an 8-bit RGB PNG. rgb holds width*height*3 bytes, row-major, row 0 = top row.
void write_png_rgb(const std::string& path, int width, int height, const unsigned char* rgb);

// Write a 16-bit greyscale PNG. grey holds width*height samples, row-major, row 0 = top row.
void write_png_grey16(const std::string& path, int width, int height, const unsigned short* grey);

// How write_field_png draws a field.
struct FieldImageStyle {
  Colormap colormap = Colormap::viridis;
  int scale = 1;         // each cell becomes scale x scale pixels (nearest neighbour), 1..64
  bool colorbar = false; // a vertical colour bar with the lo, middle and hi values on the right
  int bits = 8;          // 8: RGB through the colour map; 16: 16-bit grey (no map, no bar)
};

// Write a scalar field as a PNG. field[i + nx*j], j = 0 is the bottom row. Each value maps to
// t = (v-lo)/(hi-lo) (clamped to [0,1]); if hi <= lo (or either bound is NaN) every finite value
// maps to t = 0.5. NaN values appear magenta (8-bit) or black (16-bit grey).
void write_field_png(const std::string& path, int nx, int ny, const double* field, double lo,
                     double hi, const FieldImageStyle& style = {});

// The colour-bar labels of a range: lo, the middle and hi, each printed with %.3g.
std::vector<std::string> colorbar_labels(double lo, double hi);

// A greyscale image with values in [0, 1]; value[i + width*j], j = 0 is the BOTTOM row.
struct GreyImage {
  int width = 0, height = 0;
  std::vector<double> value;
};

// Read any PNG (any bit depth, grey/RGB/palette, with or without alpha) as grey values in
// [0, 1]. Palette images are expanded to RGB, alpha (and tRNS transparency) is ignored, 16-bit
// samples keep their full precision. Colour pixels become luminance 0.2126 R + 0.7152 G +
// 0.0722 B, computed on the stored (gamma-encoded) sample values; no gamma correction.
GreyImage read_png_grey(const std::string& path);

// Bilinear sample of img at (u, v) in [0, 1]^2. u = 0 is the centre of the left-most pixel
// column and u = 1 the centre of the right-most (pixel coordinate x = u*(width-1)); v = 0 is the
// centre of the bottom row j = 0 and v = 1 the centre of the top row (y = v*(height-1)).
// u and v are clamped to [0, 1] (NaN is treated as 0). A 1-pixel dimension is constant along it.
// Throws std::invalid_argument for an empty image.
double sample_bilinear(const GreyImage& img, double u, double v);

} // namespace morphogen::io
