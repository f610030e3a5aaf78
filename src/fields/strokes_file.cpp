#include "fields/strokes_file.hpp"

#include "core/options.hpp"
#include "core/user_error.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace morphogen {

std::string read_stroke_file_text(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw UserError("strokes file " + path + ": not a regular file (a directory or a device)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("strokes file " + path + ": cannot be read (missing file?)");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string line_column(const std::string& text, std::size_t offset) {
  std::size_t line = 1, col = 1;
  for (std::size_t p = 0; p < offset && p < text.size(); ++p) {
    if (text[p] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

void check_stroke(const std::string& path, const StrokePolyline& s, std::size_t index) {
  const std::string which = "strokes file " + path + ": stroke " + std::to_string(index + 1);
  if (s.empty()) throw UserError(which + " is empty (no points); allowed: at least 2 points");
  if (s.size() < 4) throw UserError(which + " has 1 point; allowed: at least 2 (a direction)");
  for (std::size_t p = 2; p < s.size(); p += 2)
    if (s[p] != s[0] || s[p + 1] != s[1]) return;
  throw UserError(which + " has no length (all points equal); allowed: 2 distinct points");
}

namespace {

std::string extension(const std::string& path) {
  const auto slash = path.find_last_of('/'), dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower_case(path.substr(dot + 1));
}

} // namespace

std::vector<StrokePolyline> parse_strokes(const std::string& path, const std::string& text,
                                          double Lx, double Ly, double hx, double hy) {
  const std::string ext = extension(path);
  std::vector<StrokePolyline> strokes;
  if (ext == "json")
    strokes = parse_strokes_json(path, text, Lx, Ly, hx, hy);
  else if (ext == "svg")
    strokes = parse_strokes_svg(path, text, Lx, Ly);
  else
    throw UserError("strokes file " + path + ": unknown format '." + ext +
                    "', allowed: .json or .svg");
  if (strokes.empty()) throw UserError("strokes file " + path + ": no strokes");
  for (std::size_t s = 0; s < strokes.size(); ++s)
    check_stroke(path, strokes[s], s);
  return strokes;
}

} // namespace morphogen
