// SVG stroke files (format in strokes_file.hpp): the d="..." of every <path>, each subpath one
// polyline (curves flattened), mapped from the viewBox onto the domain with y flipped.
#include "core/user_error.hpp"
#include "fields/strokes_file.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <regex>

namespace morphogen {

namespace {

constexpr int kCurveSegments = 32; // segments per flattened Bezier curve

struct PathReader {
  const std::string& path; // the file, for messages
  const std::string& text; // the whole file
  std::size_t p, end;      // the d attribute: text[p, end)
  std::vector<StrokePolyline> strokes;
  double cx = 0, cy = 0, sx = 0, sy = 0; // current point, subpath start
  double px = 0, py = 0;                 // last control point (for S and T)
  char prev = 0;

  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    throw UserError("strokes file " + path + ": " + line_column(text, at) + ": " + what);
  }
  void skip() {
    while (p < end && (std::isspace(static_cast<unsigned char>(text[p])) || text[p] == ','))
      ++p;
  }
  bool number_next() {
    skip();
    return p < end && (std::isdigit(static_cast<unsigned char>(text[p])) || text[p] == '.' ||
                       text[p] == '-' || text[p] == '+');
  }
  // One SVG number: [sign] digits [. digits] [e [sign] digits].
  double number() {
    skip();
    const std::size_t s = p;
    std::size_t q = p;
    const auto digits = [&] {
      const std::size_t d = q;
      while (q < end && std::isdigit(static_cast<unsigned char>(text[q])))
        ++q;
      return q > d;
    };
    if (q < end && (text[q] == '-' || text[q] == '+')) ++q;
    bool any = digits();
    if (q < end && text[q] == '.') {
      ++q;
      any = digits() || any;
    }
    if (!any) fail(s, "expected a number in the path data");
    if (q < end && (text[q] == 'e' || text[q] == 'E')) {
      std::size_t r = q + 1;
      if (r < end && (text[r] == '-' || text[r] == '+')) ++r;
      if (r < end && std::isdigit(static_cast<unsigned char>(text[r]))) {
        q = r;
        digits();
      }
    }
    p = q;
    return std::strtod(text.substr(s, q - s).c_str(), nullptr);
  }
  void point(double x, double y) {
    if (strokes.empty()) strokes.emplace_back();
    strokes.back().push_back(x);
    strokes.back().push_back(y);
    cx = x, cy = y;
  }
  void move_to(double x, double y) {
    strokes.emplace_back();
    sx = x, sy = y;
    point(x, y);
  }
  void line_to(double x, double y) {
    if (strokes.empty() || strokes.back().empty()) move_to(cx, cy);
    point(x, y);
  }
  // Cubic Bezier from the current point, flattened.
  void cubic(double x1, double y1, double x2, double y2, double x, double y) {
    const double x0 = cx, y0 = cy;
    for (int s = 1; s <= kCurveSegments; ++s) {
      const double t = static_cast<double>(s) / kCurveSegments, u = 1 - t;
      line_to(u * u * u * x0 + 3 * u * u * t * x1 + 3 * u * t * t * x2 + t * t * t * x,
              u * u * u * y0 + 3 * u * u * t * y1 + 3 * u * t * t * y2 + t * t * t * y);
    }
    px = x2, py = y2;
  }
  void quadratic(double x1, double y1, double x, double y) {
    const double x0 = cx, y0 = cy;
    cubic(x0 + 2.0 / 3 * (x1 - x0), y0 + 2.0 / 3 * (y1 - y0), x + 2.0 / 3 * (x1 - x),
          y + 2.0 / 3 * (y1 - y), x, y);
    px = x1, py = y1;
  }
  void command(char c, std::size_t at);
  void run();
};

void PathReader::command(char c, std::size_t at) {
  const bool rel = std::islower(static_cast<unsigned char>(c));
  const double ox = rel ? cx : 0, oy = rel ? cy : 0;
  const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const bool smooth_c = prev == 'C' || prev == 'S', smooth_q = prev == 'Q' || prev == 'T';
  double a[6];
  const auto read = [&](int n) {
    for (int k = 0; k < n; ++k)
      a[k] = number() + (k % 2 == 0 ? ox : oy);
  };
  switch (u) {
  case 'M':
    read(2);
    move_to(a[0], a[1]);
    break;
  case 'L':
    read(2);
    line_to(a[0], a[1]);
    break;
  case 'H':
    line_to(number() + ox, cy);
    break;
  case 'V':
    line_to(cx, number() + oy);
    break;
  case 'C':
    read(6);
    cubic(a[0], a[1], a[2], a[3], a[4], a[5]);
    break;
  case 'S':
    read(4);
    cubic(smooth_c ? 2 * cx - px : cx, smooth_c ? 2 * cy - py : cy, a[0], a[1], a[2], a[3]);
    break;
  case 'Q':
    read(4);
    quadratic(a[0], a[1], a[2], a[3]);
    break;
  case 'T':
    read(2);
    quadratic(smooth_q ? 2 * cx - px : cx, smooth_q ? 2 * cy - py : cy, a[0], a[1]);
    break;
  case 'Z':
    line_to(sx, sy);
    strokes.emplace_back(); // a command after Z starts a new subpath at the start point
    break;
  default:
    fail(at, std::string("unsupported path command '") + c +
                 "', allowed: M L H V C S Q T Z (and lower case)");
  }
  prev = u;
}

void PathReader::run() {
  char c = 0;
  while (true) {
    skip();
    if (p >= end) break;
    const std::size_t at = p;
    if (std::isalpha(static_cast<unsigned char>(text[p])))
      c = text[p++];
    else if (c == 0 || c == 'Z' || c == 'z')
      fail(at, "expected a path command letter (the data starts with M)");
    command(c, at);
    if (c == 'M') c = 'L'; // further pairs after M are lines
    if (c == 'm') c = 'l';
  }
  std::erase_if(strokes, [](const StrokePolyline& s) { return s.size() <= 2; });
}

// The viewBox (x, y, w, h) of the <svg> element, or its width/height.
std::array<double, 4> view_box(const std::string& path, const std::string& text) {
  static const std::regex vb_re(R"(viewBox\s*=\s*["']\s*([^"']*)["'])");
  static const std::regex wh_re(
      R"(<svg\b[^>]*?\bwidth\s*=\s*["']\s*([0-9.eE+\-]+)[a-z]*\s*["'][^>]*?\bheight\s*=\s*["']\s*([0-9.eE+\-]+))");
  std::smatch m;
  std::array<double, 4> vb{0, 0, 0, 0};
  if (std::regex_search(text, m, vb_re)) {
    std::string s = m[1].str();
    for (char& c : s)
      if (c == ',') c = ' ';
    char* q = s.data();
    for (double& v : vb)
      v = std::strtod(q, &q);
  } else if (std::regex_search(text, m, wh_re)) {
    vb[2] = std::strtod(m[1].str().c_str(), nullptr);
    vb[3] = std::strtod(m[2].str().c_str(), nullptr);
  }
  if (!(vb[2] > 0 && vb[3] > 0 && std::isfinite(vb[2]) && std::isfinite(vb[3])))
    throw UserError("strokes file " + path +
                    ": no usable viewBox=\"x y w h\" (or width and height) on <svg>");
  return vb;
}

} // namespace

std::vector<StrokePolyline> parse_strokes_svg(const std::string& path, const std::string& text,
                                              double Lx, double Ly) {
  if (const auto t = text.find("transform"); t != std::string::npos)
    throw UserError("strokes file " + path + ": " + line_column(text, t) +
                    ": transform attributes are not supported (apply them to the paths first)");
  const std::array<double, 4> vb = view_box(path, text);
  static const std::regex d_re(R"(<path\b[^>]*?\sd\s*=\s*(["']))");
  std::vector<StrokePolyline> out;
  for (std::sregex_iterator it(text.begin(), text.end(), d_re), e; it != e; ++it) {
    const std::size_t start = static_cast<std::size_t>(it->position(0) + it->length(0));
    const std::size_t stop = text.find((*it)[1].str()[0], start);
    if (stop == std::string::npos)
      throw UserError("strokes file " + path + ": " + line_column(text, start) +
                      ": unterminated d attribute");
    PathReader r{path, text, start, stop, {}};
    r.run();
    for (StrokePolyline& s : r.strokes) {
      for (std::size_t k = 0; k < s.size(); k += 2) {
        s[k] = (s[k] - vb[0]) / vb[2] * Lx;
        s[k + 1] = (1.0 - (s[k + 1] - vb[1]) / vb[3]) * Ly;
      }
      out.push_back(std::move(s));
    }
  }
  if (out.empty()) throw UserError("strokes file " + path + ": no <path d=\"...\"> with a stroke");
  return out;
}

} // namespace morphogen
