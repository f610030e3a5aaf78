// JSON stroke files (format in strokes_file.hpp), read with nlohmann::json.
#include "core/json_depth.hpp"
#include "core/user_error.hpp"
#include "fields/strokes_file.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace morphogen {

namespace {

using json = nlohmann::json;

// nlohmann's message without its "[json.exception...] parse error at line L, column C: " prefix
// and on one line (it reports the byte position; our own line/column replaces it).
std::string parse_reason(const std::string& what) {
  std::string r = what;
  if (const auto p = r.find(": "); p != std::string::npos && r.rfind("[json.", 0) == 0)
    r = r.substr(p + 2);
  else if (const auto q = r.find("] "); q != std::string::npos && r.rfind("[json.", 0) == 0)
    r = r.substr(q + 2); // "[json.exception.out_of_range.406] number overflow ..."
  for (char& c : r)
    if (c == '\n' || c == '\r') c = ' ';
  return r;
}

json parse_document(const std::string& path, const std::string& text) {
  if (const int depth = json_nesting_depth(text); depth > kMaxJsonDepth)
    throw UserError("strokes file " + path + ": nested " + std::to_string(depth) +
                    " levels deep, allowed at most " + std::to_string(kMaxJsonDepth));
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    const std::size_t at = e.byte > 0 ? e.byte - 1 : 0; // e.byte: 1-based byte of the error
    throw UserError("strokes file " + path + ": " + line_column(text, at) + ": " +
                    parse_reason(e.what()));
  } catch (const json::exception& e) { // e.g. a number that overflows a double (1e400)
    throw UserError("strokes file " + path + ": " + parse_reason(e.what()));
  }
}

// Scale of "units": domain -> (1, 1); cells -> (hx, hy); fraction -> (Lx, Ly).
void read_units(const std::string& where, const json& doc, const double scale[6], double& sx,
                double& sy) {
  sx = sy = 1.0;
  if (!doc.contains("units")) return;
  const json& u = doc["units"];
  const int k = u == "domain" ? 0 : u == "cells" ? 1 : u == "fraction" ? 2 : -1;
  if (k < 0)
    throw UserError(where + "\"units\": " + u.dump() +
                    ", allowed: \"domain\", \"cells\" or \"fraction\"");
  sx = scale[2 * k];
  sy = scale[2 * k + 1];
}

StrokePolyline read_stroke(const std::string& where, const json& s, double sx, double sy) {
  if (!s.is_object() || !s.contains("points"))
    throw UserError(where + ": expected an object {\"points\": [[x, y], ...]}");
  for (const auto& [k, v] : s.items())
    if (k != "points" && k != "closed")
      throw UserError(where + ": unknown key \"" + k + "\", allowed: points, closed");
  const json& pts = s["points"];
  if (!pts.is_array()) throw UserError(where + ".points: expected an array of [x, y]");
  StrokePolyline out;
  for (std::size_t p = 0; p < pts.size(); ++p) {
    const json& q = pts[p];
    if (!q.is_array() || q.size() != 2 || !q[0].is_number() || !q[1].is_number())
      throw UserError(where + ".points[" + std::to_string(p) + "]: " + q.dump() +
                      ", expected [x, y] (two numbers)");
    out.push_back(q[0].get<double>() * sx);
    out.push_back(q[1].get<double>() * sy);
    if (!std::isfinite(out[out.size() - 2]) || !std::isfinite(out.back()))
      throw UserError(where + ".points[" + std::to_string(p) + "]: not finite");
  }
  if (s.contains("closed")) {
    if (!s["closed"].is_boolean()) throw UserError(where + ".closed: expected true or false");
    if (s["closed"].get<bool>() && out.size() >= 4) {
      out.push_back(out[0]);
      out.push_back(out[1]);
    }
  }
  return out;
}

} // namespace

std::vector<StrokePolyline> parse_strokes_json(const std::string& path, const std::string& text,
                                               double Lx, double Ly, double hx, double hy) {
  const json doc = parse_document(path, text);
  const std::string where = "strokes file " + path + ": ";
  if (doc.is_object())
    for (const auto& [k, v] : doc.items())
      if (k != "strokes" && k != "units")
        throw UserError(where + "unknown key \"" + k + "\", allowed: strokes, units");
  if (!doc.is_object() || !doc.contains("strokes"))
    throw UserError(where + "expected an object with \"strokes\": [{\"points\": [[x, y], ...]}]");
  double sx, sy;
  const double scale[6] = {1.0, 1.0, hx, hy, Lx, Ly};
  read_units(where, doc, scale, sx, sy);
  const json& list = doc["strokes"];
  if (!list.is_array()) throw UserError(where + "\"strokes\": expected an array of strokes");
  std::vector<StrokePolyline> out;
  for (std::size_t s = 0; s < list.size(); ++s)
    out.push_back(read_stroke(where + "strokes[" + std::to_string(s) + "]", list[s], sx, sy));
  return out;
}

} // namespace morphogen
