// PNG input/output with libpng. See png_file.hpp for the contract.
//
// libpng reports errors by longjmp back to a setjmp point. To keep that well-defined in C++,
// every setjmp lives in a small helper (png_write_all, png_read_header, png_read_pixels) whose
// frame holds only raw pointers and scalars, and the libpng callbacks below (error, read,
// write, flush) create no objects with destructors. The outer functions own the FILE*, the
// libpng structs and the buffers, and turn a failure into morphogen::UserError.
#include "io/png_file.hpp"

#include "core/user_error.hpp"
#include "io/colormap.hpp"

#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace morphogen::io {

namespace {

// Trivially destructible state shared with the libpng callbacks.
struct PngIo {
  std::FILE* fp = nullptr;
  char msg[256] = {}; // reason for the first failure, filled by the callbacks
};

void set_msg(PngIo* io, const char* msg) {
  if (io != nullptr && io->msg[0] == '\0')
    std::snprintf(io->msg, sizeof io->msg, "%s", msg != nullptr ? msg : "libpng error");
}

[[noreturn]] void on_error(png_structp png, png_const_charp msg) {
  set_msg(static_cast<PngIo*>(png_get_error_ptr(png)), msg);
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}

void on_write(png_structp png, png_bytep data, png_size_t length) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  errno = 0;
  if (std::fwrite(data, 1, length, io->fp) != length) {
    set_msg(io, errno != 0 ? std::strerror(errno) : "write failed");
    png_error(png, io->msg);
  }
}

void on_flush(png_structp png) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  errno = 0;
  if (std::fflush(io->fp) != 0) {
    set_msg(io, errno != 0 ? std::strerror(errno) : "flush failed");
    png_error(png, io->msg);
  }
}

void on_read(png_structp png, png_bytep data, png_size_t length) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  errno = 0;
  if (std::fread(data, 1, length, io->fp) != length) {
    if (std::ferror(io->fp))
      set_msg(io, errno != 0 ? std::strerror(errno) : "read failed");
    else
      set_msg(io, "unexpected end of file (truncated PNG)");
    png_error(png, io->msg);
  }
}

// Writes the whole image (rows of `stride` bytes, row 0 the top row) with the given bit depth
// and colour type. False on a libpng error.
bool png_write_all(png_structp png, png_infop info, PngIo* io, int width, int height, int depth,
                   int colour, std::size_t stride, const unsigned char* pixels) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, io, on_write, on_flush);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), depth,
               colour, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Quick-looks favour speed: zlib level 1 and the one SUB filter (smooth fields compress well
  // with it) instead of level 6 and trying all five filters on every row.
  png_set_compression_level(png, 1);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_write_info(png, info);
  for (int r = 0; r < height; ++r)
    png_write_row(png, pixels + stride * static_cast<std::size_t>(r));
  png_write_end(png, nullptr);
  return true;
}

struct ReadLayout {
  png_uint_32 width = 0, height = 0;
  int channels = 0, bit_depth = 0;
  std::size_t rowbytes = 0;
};

// Reads the header (after the 8 signature bytes) and sets transforms so rows come out as
// 8- or 16-bit grey or RGB without alpha. False on a libpng error.
bool png_read_header(png_structp png, png_infop info, PngIo* io, ReadLayout* out) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, io, on_read);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  const int colour = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  // Palette expansion turns tRNS into an alpha channel; strip any alpha channel.
  if ((colour & PNG_COLOR_MASK_ALPHA) != 0 || png_get_valid(png, info, PNG_INFO_tRNS) != 0)
    png_set_strip_alpha(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  out->width = png_get_image_width(png, info);
  out->height = png_get_image_height(png, info);
  out->channels = png_get_channels(png, info);
  out->bit_depth = png_get_bit_depth(png, info);
  out->rowbytes = png_get_rowbytes(png, info);
  return true;
}

bool png_read_pixels(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

std::string write_failure(const std::string& path, const std::string& reason) {
  return "cannot write PNG file '" + path + "': " + reason;
}

std::string read_failure(const std::string& path, const std::string& reason) {
  return "cannot read PNG file '" + path + "': " + reason;
}

struct FileCloser {
  std::FILE* fp;
  ~FileCloser() {
    if (fp != nullptr) std::fclose(fp);
  }
};

struct ReadStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~ReadStructs() {
    if (png != nullptr) png_destroy_read_struct(&png, info != nullptr ? &info : nullptr, nullptr);
  }
};

// Writes a PNG of any layout to path + ".tmp" and renames it onto path (see the header).
void write_png_pixels(const std::string& path, int width, int height, int depth, int colour,
                      std::size_t stride, const unsigned char* pixels) {
  if (width <= 0 || height <= 0)
    throw UserError(write_failure(path, "invalid image size " + std::to_string(width) + "x" +
                                            std::to_string(height)));
  if (pixels == nullptr) throw UserError(write_failure(path, "no pixel data"));

  const std::string tmp = path + ".tmp";
  std::FILE* fp = std::fopen(tmp.c_str(), "wb");
  if (fp == nullptr) throw UserError(write_failure(path, std::strerror(errno)));

  PngIo io;
  io.fp = fp;
  std::string reason;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &io, on_error, on_warning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr)
    reason = "cannot initialise libpng (out of memory)";
  else if (!png_write_all(png, info, &io, width, height, depth, colour, stride, pixels))
    reason = io.msg[0] != '\0' ? io.msg : "libpng error";
  if (png != nullptr) png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);

  errno = 0;
  if (std::fclose(fp) != 0 && reason.empty())
    reason = errno != 0 ? std::strerror(errno) : "close failed";
  if (reason.empty() && std::rename(tmp.c_str(), path.c_str()) != 0)
    reason = std::string("cannot rename from '") + tmp + "': " + std::strerror(errno);
  if (!reason.empty()) {
    std::remove(tmp.c_str());
    throw UserError(write_failure(path, reason));
  }
}

// A 5x7 bitmap font for the colour-bar labels: rows top to bottom, bit 4 the left column.
struct Glyph {
  char c;
  unsigned char rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
    {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
    {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
    {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
    {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
    {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0, 0, 0, 0, 0, 0x0C, 0x0C}},
    {'-', {0, 0, 0, 0x1F, 0, 0, 0}},
    {'+', {0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0}},
    {'e', {0, 0, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'n', {0, 0, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'a', {0, 0, 0x0E, 0x01, 0x0F, 0x11, 0x0F}},
    {'i', {0x04, 0, 0x0C, 0x04, 0x04, 0x04, 0x0E}},
    {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}},
};

// An RGB canvas, row 0 the top row.
struct Canvas {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  unsigned char* at(int x, int y) {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x));
  }
};

// Draws `text` in black with its top-left corner at (x, y), each font pixel f x f.
void draw_text(Canvas& c, int x, int y, const std::string& text, int f) {
  for (char ch : text) {
    for (const Glyph& g : kFont) {
      if (g.c != ch) continue;
      for (int r = 0; r < 7; ++r)
        for (int b = 0; b < 5; ++b)
          if ((g.rows[r] >> (4 - b)) & 1)
            for (int dy = 0; dy < f; ++dy)
              for (int dx = 0; dx < f; ++dx) {
                const int px = x + b * f + dx, py = y + r * f + dy;
                if (px >= 0 && px < c.width && py >= 0 && py < c.height) {
                  unsigned char* p = c.at(px, py);
                  p[0] = p[1] = p[2] = 0;
                }
              }
    }
    x += 6 * f;
  }
}

// Maps a field value to t in [0, 1] (NaN stays NaN); see write_field_png.
struct RangeMap {
  double lo, scale;
  bool degenerate;
  RangeMap(double lo_, double hi_) : lo(lo_), scale(0), degenerate(!(hi_ > lo_)) {
    if (!degenerate) scale = 1.0 / (hi_ - lo_);
  }
  double operator()(double v) const {
    return std::isnan(v) ? v : degenerate ? 0.5 : (v - lo) * scale;
  }
};

// The field upscaled into the top-left of a white canvas, with the colour bar if asked for.
Canvas field_canvas(int nx, int ny, const double* field, double lo, double hi,
                    const FieldImageStyle& st) {
  const int w = nx * st.scale, h = ny * st.scale;
  const int f = std::clamp(h / 128, 1, 8); // font pixel size
  std::vector<std::string> labels;
  int bar_x = w, label_x = w;
  Canvas c;
  c.width = w;
  c.height = h;
  if (st.colorbar) {
    labels = colorbar_labels(lo, hi);
    std::size_t chars = 0;
    for (const auto& l : labels)
      chars = std::max(chars, l.size());
    const int gap = 4 * f, bar_w = std::max(8 * f, h / 16);
    bar_x = w + gap;
    label_x = bar_x + bar_w + gap;
    c.width = label_x + static_cast<int>(chars) * 6 * f + gap;
    c.height = std::max(h, 2 * 7 * f + 2 * f);
  }
  c.rgb.assign(static_cast<std::size_t>(c.width) * c.height * 3, 255);
  const RangeMap map(lo, hi);
  for (int y = 0; y < h; ++y) {
    const double* src = field + static_cast<std::size_t>(nx) * (ny - 1 - y / st.scale);
    for (int x = 0; x < w; ++x)
      colormap_rgb(st.colormap, map(src[x / st.scale]), c.at(x, y));
  }
  if (!st.colorbar) return c;
  for (int y = 0; y < h; ++y) {
    const double t = h > 1 ? 1.0 - static_cast<double>(y) / (h - 1) : 0.5;
    for (int x = bar_x; x < label_x - 4 * f; ++x)
      colormap_rgb(st.colormap, t, c.at(x, y));
  }
  draw_text(c, label_x, 0, labels[2], f);                          // hi at the top
  draw_text(c, label_x, std::max(h, 7 * f) - 7 * f, labels[0], f); // lo at the bottom
  if (h >= 4 * 7 * f) draw_text(c, label_x, h / 2 - 7 * f / 2, labels[1], f);
  return c;
}

} // namespace

void write_png_rgb(const std::string& path, int width, int height, const unsigned char* rgb) {
  write_png_pixels(path, width, height, 8, PNG_COLOR_TYPE_RGB,
                   static_cast<std::size_t>(std::max(width, 0)) * 3, rgb);
}

void write_png_grey16(const std::string& path, int width, int height, const unsigned short* grey) {
  if (grey == nullptr || width <= 0 || height <= 0) {
    write_png_pixels(path, width, height, 16, PNG_COLOR_TYPE_GRAY, 0, nullptr);
    return;
  }
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<unsigned char> be(2 * n); // PNG stores 16-bit samples big-endian
  for (std::size_t i = 0; i < n; ++i) {
    be[2 * i] = static_cast<unsigned char>(grey[i] >> 8);
    be[2 * i + 1] = static_cast<unsigned char>(grey[i] & 0xFF);
  }
  write_png_pixels(path, width, height, 16, PNG_COLOR_TYPE_GRAY,
                   2 * static_cast<std::size_t>(width), be.data());
}

std::vector<std::string> colorbar_labels(double lo, double hi) {
  std::vector<std::string> out;
  for (double v : {lo, 0.5 * (lo + hi), hi}) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    out.emplace_back(buf);
  }
  return out;
}

void write_field_png(const std::string& path, int nx, int ny, const double* field, double lo,
                     double hi, const FieldImageStyle& style) {
  if (nx <= 0 || ny <= 0)
    throw UserError(
        write_failure(path, "invalid image size " + std::to_string(nx) + "x" + std::to_string(ny)));
  if (field == nullptr) throw UserError(write_failure(path, "no field data"));
  if (style.scale < 1 || style.scale > 64 || (style.bits != 8 && style.bits != 16))
    throw UserError(write_failure(path, "invalid style (scale " + std::to_string(style.scale) +
                                            ", bits " + std::to_string(style.bits) + ")"));
  if (style.bits == 16) {
    const int w = nx * style.scale, h = ny * style.scale;
    const RangeMap map(lo, hi);
    std::vector<unsigned short> grey(static_cast<std::size_t>(w) * h);
    for (int y = 0; y < h; ++y) {
      const double* src = field + static_cast<std::size_t>(nx) * (ny - 1 - y / style.scale);
      for (int x = 0; x < w; ++x) {
        const double t = map(src[x / style.scale]);
        const double c = std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0);
        grey[static_cast<std::size_t>(y) * w + x] =
            static_cast<unsigned short>(std::lround(c * 65535.0));
      }
    }
    write_png_grey16(path, w, h, grey.data());
    return;
  }
  const Canvas c = field_canvas(nx, ny, field, lo, hi, style);
  write_png_rgb(path, c.width, c.height, c.rgb.data());
}

GreyImage read_png_grey(const std::string& path) {
  std::FILE* fp = std::fopen(path.c_str(), "rb");
  if (fp == nullptr) throw UserError(read_failure(path, std::strerror(errno)));
  FileCloser closer{fp};

  unsigned char sig[8];
  errno = 0;
  const std::size_t got = std::fread(sig, 1, sizeof sig, fp);
  if (got != sizeof sig && std::ferror(fp))
    throw UserError(read_failure(path, errno != 0 ? std::strerror(errno) : "read failed"));
  if (got != sizeof sig || png_sig_cmp(sig, 0, sizeof sig) != 0)
    throw UserError(read_failure(path, "not a PNG file"));

  PngIo io;
  io.fp = fp;
  ReadStructs s;
  s.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &io, on_error, on_warning);
  if (s.png != nullptr) s.info = png_create_info_struct(s.png);
  if (s.png == nullptr || s.info == nullptr)
    throw UserError(read_failure(path, "cannot initialise libpng (out of memory)"));

  ReadLayout lay;
  if (!png_read_header(s.png, s.info, &io, &lay))
    throw UserError(read_failure(path, io.msg[0] != '\0' ? io.msg : "libpng error"));
  if (lay.width == 0 || lay.height == 0 || lay.channels < 1 || lay.channels > 4 ||
      (lay.bit_depth != 8 && lay.bit_depth != 16))
    throw UserError(read_failure(path, "unsupported PNG layout"));
  constexpr std::size_t max_pixels = std::size_t{1} << 28;
  const std::size_t w = lay.width, h = lay.height;
  if (w * h > max_pixels)
    throw UserError(read_failure(path, "image too large (" + std::to_string(w) + "x" +
                                           std::to_string(h) + " pixels)"));

  std::vector<unsigned char> buf(lay.rowbytes * h);
  std::vector<png_bytep> rows(h);
  for (std::size_t r = 0; r < h; ++r)
    rows[r] = buf.data() + lay.rowbytes * r;
  if (!png_read_pixels(s.png, rows.data()))
    throw UserError(read_failure(path, io.msg[0] != '\0' ? io.msg : "libpng error"));

  GreyImage img;
  img.width = static_cast<int>(w);
  img.height = static_cast<int>(h);
  img.value.resize(w * h);
  const int nc = lay.channels;
  const bool wide = lay.bit_depth == 16;
  const double max = wide ? 65535.0 : 255.0;
  for (std::size_t r = 0; r < h; ++r) {
    const unsigned char* row = rows[r];
    double* out = img.value.data() + w * (h - 1 - r); // file row 0 is the top: j = h-1
    for (std::size_t i = 0; i < w; ++i) {
      double c[3];
      const int ncol = nc >= 3 ? 3 : 1; // grey (+alpha) or RGB (+alpha); alpha ignored
      for (int k = 0; k < ncol; ++k) {
        const std::size_t idx = i * static_cast<std::size_t>(nc) + static_cast<std::size_t>(k);
        const unsigned s16 = wide ? (unsigned{row[2 * idx]} << 8) | row[2 * idx + 1] : row[idx];
        c[k] = s16 / max;
      }
      out[i] = ncol == 1 ? c[0] : 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    }
  }
  return img;
}

double sample_bilinear(const GreyImage& img, double u, double v) {
  if (img.width <= 0 || img.height <= 0 ||
      img.value.size() != static_cast<std::size_t>(img.width) * img.height)
    throw std::invalid_argument("sample_bilinear: empty or inconsistent image");
  const auto unit = [](double a) { return a >= 0.0 ? (a <= 1.0 ? a : 1.0) : 0.0; }; // NaN -> 0
  const double x = unit(u) * (img.width - 1);
  const double y = unit(v) * (img.height - 1);
  const int i0 = std::min(static_cast<int>(x), img.width - 1);
  const int j0 = std::min(static_cast<int>(y), img.height - 1);
  const int i1 = std::min(i0 + 1, img.width - 1);
  const int j1 = std::min(j0 + 1, img.height - 1);
  const double fx = x - i0, fy = y - j0;
  const auto at = [&](int i, int j) {
    return img.value[static_cast<std::size_t>(i) + static_cast<std::size_t>(img.width) * j];
  };
  const double bottom = (1.0 - fx) * at(i0, j0) + fx * at(i1, j0);
  const double top = (1.0 - fx) * at(i0, j1) + fx * at(i1, j1);
  return (1.0 - fy) * bottom + fy * top;
}

} // namespace morphogen::io
