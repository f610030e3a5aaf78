// Stroke files: polylines for strokes(...) / strokes_distance(...) (strokes_field.hpp).
//
// JSON (.json):
//   {"units": "domain" | "cells" | "fraction",  optional, default "domain"
//    "strokes": [{"points": [[x, y], ...],   at least two distinct points
//                 "closed": false}, ...]}    optional: join the last point to the first
//   "domain": x, y in the domain's length units (cell (i, j) spans [i hx, (i+1) hx] x ...);
//   "cells": in cells (x = 10.5 is the centre of cell i = 10); "fraction": the unit square
//   stretched over the domain (the same stroke on any grid). y points up (increasing j).
// SVG (.svg): every <path d="..."> of the file, each subpath one stroke. Path commands M L H V
//   C S Q T Z (and their relative lower-case forms); curves are flattened into 32 segments each.
//   A (arcs) and transform="..." attributes are refused (apply transforms to the paths first).
//   The viewBox (or width/height when there is none) is stretched over the domain, y flipped,
//   so the picture appears as drawn in the PNG quick-looks.
// Errors: UserError "strokes file PATH: line L, column C: what" (syntax), or naming the stroke.
#pragma once

#include "fields/strokes_field.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace morphogen {

// The whole file, or UserError naming the path when it cannot be read.
std::string read_stroke_file_text(const std::string& path);

// Strokes in domain units from a file's text; the extension of `path` picks the format.
std::vector<StrokePolyline> parse_strokes(const std::string& path, const std::string& text,
                                          double Lx, double Ly, double hx, double hy);

std::vector<StrokePolyline> parse_strokes_json(const std::string& path, const std::string& text,
                                               double Lx, double Ly, double hx, double hy);
std::vector<StrokePolyline> parse_strokes_svg(const std::string& path, const std::string& text,
                                              double Lx, double Ly);

// "line L, column C" of byte offset `offset` (0-based) in text (lines and columns from 1).
std::string line_column(const std::string& text, std::size_t offset);

// Refuses (UserError) a stroke with fewer than two points or no two distinct points.
void check_stroke(const std::string& path, const StrokePolyline& s, std::size_t index);

} // namespace morphogen
